"""The XIRP message set as plain data: no XML, no sockets.

Six messages (``docs/xirp.md``): :class:`Hello`, :class:`Request`, :class:`Response`,
:class:`Event`, :class:`ErrorMessage` and :class:`Bye`. Parameters and results are
typed values: ``decimal`` (:class:`float`, or :class:`~decimal.Decimal` when sent),
``integer`` (:class:`int`), ``boolean`` (:class:`bool`), ``string`` (:class:`str`)
and ``pose`` (:class:`Pose`, six numbers). :mod:`~plugnproduce.protocols.xirp.codec`
turns these into bytes and back.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime
from decimal import Decimal
from typing import NamedTuple, TypeAlias

from plugnproduce.errors import DescriptionError, ProtocolError, excerpt
from plugnproduce.protocols.files import DeviceFiles

NAMESPACE = "urn:plugnproduce-org:xirp:1"
"""XML namespace of every XIRP message (version 1)."""

VERSION = 1
"""Protocol version announced in :class:`Hello`."""

DESCRIBE = "describe"
"""The request every device answers with its Turtle description and SCXML chart."""

STATE = "state"
"""The request a device answers with its current state: the id of its device state chart's state, as the
string result :data:`STATE_RESULT`."""

STATE_RESULT = "State"
"""The result of a :data:`STATE` response."""

TURTLE = "text/turtle"
"""Media type of the Turtle description in a ``describe`` response."""

SCXML = "application/scxml+xml"
"""Media type of the SCXML chart in a ``describe`` response."""

# Error codes. A Response's failure carries one of the first four (or a device's own);
# an ErrorMessage (protocol error) one of the last four.
NOT_ACCEPTED = "not-accepted"
"""Failure: the device does not accept this request in its current state."""
UNKNOWN_REQUEST = "unknown-request"
"""Failure: the device has no such request."""
BAD_PARAMETER = "bad-parameter"
"""Failure: a parameter is missing, unknown, of the wrong type or out of range."""
FAILED = "failed"
"""Failure: the device accepted the request but could not carry it out."""
MALFORMED = "malformed"
"""Protocol error: not well-formed XML, or not valid against the XIRP schema."""
TOO_LARGE = "too-large"
"""Protocol error: a frame longer than the receiver's maximum (the connection is closed)."""
UNEXPECTED = "unexpected"
"""Protocol error: a valid message the receiver does not take (a ``hello`` sent to a device)."""
INVALID_VALUE = "invalid-value"
"""A message that cannot be encoded (raised locally, never sent)."""

NAME_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]{0,127}")
ID_PATTERN = re.compile(r"[A-Za-z0-9_.\-]{1,64}")
CODE_PATTERN = re.compile(r"[a-z][a-z0-9\-]{0,63}")


class MessageError(ProtocolError):
    """A message that cannot be decoded (or encoded): says what was found and what was expected.

    ``code`` is the protocol error code the receiver answers with (:data:`MALFORMED`,
    :data:`TOO_LARGE`, :data:`UNEXPECTED`, :data:`INVALID_VALUE`), ``ref`` the id of
    the offending request when it could be read.
    """

    def __init__(self, message: str, code: str = MALFORMED, ref: str | None = None) -> None:
        super().__init__(message)
        self.code = code
        self.ref = ref


class Pose(NamedTuple):
    """A pose: position in metres, orientation in degrees (``x y z rx ry rz`` on the wire)."""

    x: float
    y: float
    z: float
    rx: float
    ry: float
    rz: float


Value: TypeAlias = bool | int | float | Decimal | str | Pose
"""A parameter or result value. A list or tuple of six numbers is sent as a pose."""

Params: TypeAlias = Mapping[str, Value]


@dataclass(frozen=True, slots=True)
class Hello:
    """Sent by the device on every new connection: who it is, and how to get its description."""

    device: str
    """The device id (the local name of its IRI, ``gripper``)."""
    device_class: str
    """The IRI of its class in the device taxonomy."""
    label: str | None = None
    """Its ``rdfs:label``, for people."""
    describe: str | None = DESCRIBE
    """The request that returns its description and chart; ``None`` if it serves none."""
    version: int = VERSION


@dataclass(frozen=True, slots=True)
class Request:
    """Ask the device to do something: ``name`` with typed ``params``, answered by a :class:`Response`."""

    id: str
    name: str
    params: Params = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class Document:
    """A text document carried in a response (the device's Turtle description, its chart)."""

    name: str
    media_type: str
    text: str


@dataclass(frozen=True, slots=True)
class Failure:
    """Why a request failed: a code (:data:`NOT_ACCEPTED`, …) and a text for people."""

    code: str
    text: str


@dataclass(frozen=True, slots=True)
class Response:
    """The answer to the request with the same ``id``: results, or a failure."""

    id: str
    results: Params = field(default_factory=dict)
    documents: tuple[Document, ...] = ()
    failure: Failure | None = None

    @property
    def ok(self) -> bool:
        """Whether the request succeeded."""
        return self.failure is None


@dataclass(frozen=True, slots=True)
class Event:
    """Something happened on the device. ``seq`` counts the device's events from 1; ``time`` is aware (UTC)."""

    name: str
    seq: int
    time: datetime
    params: Params = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class ErrorMessage:
    """A protocol error: the peer sent something malformed, too large or unexpected."""

    code: str
    text: str
    ref: str | None = None
    """The id of the offending request, when it could be read."""


@dataclass(frozen=True, slots=True)
class Bye:
    """The sender is about to close the connection."""

    reason: str | None = None


Message: TypeAlias = Hello | Request | Response | Event | ErrorMessage | Bye


def documents_of(files: DeviceFiles) -> tuple[Document, Document]:
    """The two documents of a ``describe`` response."""
    return (Document(files.description_name, TURTLE, files.description),
            Document(files.chart_name, SCXML, files.chart))


def files_from_documents(documents: tuple[Document, ...], what: str) -> DeviceFiles:
    """Pick the Turtle description and the SCXML chart out of a ``describe`` response."""
    by_type: dict[str, Document] = {}
    for document in documents:
        by_type.setdefault(document.media_type, document)
    missing = [t for t in (TURTLE, SCXML) if t not in by_type]
    if missing:
        found = ", ".join(f"{d.name} ({d.media_type})" for d in documents) or "no documents"
        raise MessageError(f"{what}: expected a {' and a '.join(missing)} document; found {found}")
    ttl, chart = by_type[TURTLE], by_type[SCXML]
    try:
        return DeviceFiles(ttl.name, ttl.text, chart.name, chart.text)
    except DescriptionError as exc:
        raise MessageError(f"{what}: {exc}", INVALID_VALUE) from exc


def parse_endpoint(endpoint: str) -> tuple[str, int]:
    """``xirp://HOST:PORT`` (a device's ``pnp:endpoint``) → ``(host, port)``."""
    match = re.fullmatch(r"xirp://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.\-]+):(\d{1,5})/?", endpoint.strip())
    if match is None or int(match.group(2)) > 65535:
        raise ProtocolError(f"endpoint {excerpt(endpoint)!r} is not an XIRP endpoint; expected xirp://HOST:PORT")
    return match.group(1).strip("[]"), int(match.group(2))


def format_endpoint(host: str, port: int) -> str:
    """``(host, port)`` → ``xirp://HOST:PORT`` (IPv6 hosts in brackets)."""
    return f"xirp://[{host}]:{port}" if ":" in host else f"xirp://{host}:{port}"
