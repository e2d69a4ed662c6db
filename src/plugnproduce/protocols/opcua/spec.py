"""How a Plug'n'Produce device looks in OPC UA: the naming rule, the value types, the endpoint and the limits.

The naming rule (``docs/opcua.md``): the device registers the namespace ``NAMESPACE_PREFIX + device id``
(index ``ns``) and has one object ``Objects/ns:DEVICE``. Below it:

* one method ``ns:NAME`` per request ``opcua.request.NAME`` of its device state chart, whose input
  arguments are the quantities the request carries (named by the quantity, typed by :data:`KINDS`);
* a String variable ``ns:State``: the id of the chart state the device is in (the state query);
* a variable ``ns:QUANTITY`` per value the device reports with its state (teach-in: the chart's
  ``<data pnp:quantity=...>``), typed as a request argument of that quantity is (a pose ``Double[6]``);
* an object ``ns:Description`` with String variables ``TurtleName``, ``Turtle``, ``ChartName`` and ``Chart``:
  the device's own description files (read, as over UPnP, within a size and time budget);
* the object is the source (``EventNotifier``) of the device's events: each ``opcua.event.NAME`` is an
  event of the type ``ns:NAME`` (a subtype of ``BaseEventType``) whose fields are the values it carries.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from typing import Any, Literal

from plugnproduce.errors import ProtocolError

NAMESPACE_PREFIX = "http://plugnproduce.org/opcua/"
"""The device's namespace URI is this plus its id."""

STATE_VARIABLE = "State"
"""The browse name of the variable that holds the id of the chart state the device is in."""

DESCRIPTION_OBJECT = "Description"
"""The browse name of the object whose String variables hold the device's own description files."""
DESCRIPTION_VARIABLES = ("TurtleName", "Turtle", "ChartName", "Chart")
"""Its variables: the Turtle's file name and text, the chart's file name and text."""
APPLICATION_URI_PREFIX = "urn:plugnproduce:device:"
"""A device's server registers with a Local Discovery Server under this plus its id."""

REGISTRATION_PERIOD = 30
"""Seconds between a device's renewals of its registration with a Local Discovery Server (whole seconds, as
asyncua renews; OPC UA asks for at most 10 minutes)."""

REQUEST_PREFIX = "opcua.request."
EVENT_PREFIX = "opcua.event."

MAX_ARRAY = 4096
"""Longest array the controller accepts in a value from a device."""
MAX_STRING = 65536
"""Longest string (characters) the controller accepts in a value from a device."""
MAX_ARGUMENTS = 64
"""Most arguments (of a method, or fields of an event) the controller reads."""
MAX_MESSAGE = 1 << 20
"""Largest OPC UA message (bytes) the controller accepts; larger ones end the connection."""
MAX_CHUNK = 65535
"""Largest chunk (bytes) of an OPC UA message the controller receives."""
MAX_CHUNKS = 16
"""Most chunks one OPC UA message may come in: with :data:`MAX_CHUNK`, at most :data:`MAX_MESSAGE` bytes."""
MAX_BROWSE = 256
"""Most references the controller reads when it browses one node (the event types, the device object)."""

Kind = Literal["double", "int", "bool", "string", "pose", "any"]
"""The OPC UA built-in type a value travels as: Double, Int64, Boolean, String, Double[6], or any (Variant)."""

_XSD = "http://www.w3.org/2001/XMLSchema#"
KINDS: dict[str, Kind] = {
    f"{_XSD}decimal": "double", f"{_XSD}double": "double", f"{_XSD}float": "double",
    f"{_XSD}integer": "int", f"{_XSD}int": "int", f"{_XSD}long": "int",
    f"{_XSD}nonNegativeInteger": "int", f"{_XSD}positiveInteger": "int",
    f"{_XSD}boolean": "bool", f"{_XSD}string": "string",
    "http://plugnproduce.org/ontology#Pose": "pose",
}
"""A request argument's datatype (``pnp:datatype``) and the OPC UA type it travels as; undeclared: any."""


def kind_of(datatype: str) -> Kind:
    """The OPC UA kind of a declared datatype IRI (an empty or unknown one travels as any Variant)."""
    return KINDS.get(datatype, "any")


@dataclass(frozen=True)
class ArgumentSpec:
    """One input argument of a method: the quantity's name and its OPC UA kind."""

    name: str
    kind: Kind = "any"


@dataclass(frozen=True)
class MethodSpec:
    """A method of the device object: a request of the chart."""

    name: str
    inputs: tuple[ArgumentSpec, ...] = ()
    outputs: tuple[str, ...] = ()
    """The values of the event the request answers with at once (its method's output arguments)."""


@dataclass(frozen=True)
class NodeSpec:
    """What a device publishes: its methods and its event types (each with the names of its fields)."""

    device: str
    methods: tuple[MethodSpec, ...] = ()
    events: dict[str, tuple[str, ...]] = field(default_factory=dict)
    reports: tuple[ArgumentSpec, ...] = ()
    """The values the device reports with its state: one variable each, beside ``State``."""

    def __post_init__(self) -> None:
        taken = {m.name for m in self.methods} | {STATE_VARIABLE, DESCRIPTION_OBJECT}
        for report in self.reports:
            if report.name in taken:
                raise ProtocolError(f"device {self.device}: the reported quantity {report.name} would be a "
                                    f"variable named like its {report.name} node; rename the quantity")

    @property
    def namespace(self) -> str:
        """The device's namespace URI."""
        return namespace_for(self.device)


def application_uri_for(device: str) -> str:
    """The application URI a device's server has (and registers with a Local Discovery Server)."""
    return APPLICATION_URI_PREFIX + device


def namespace_for(device: str) -> str:
    """The namespace URI of a device's nodes."""
    return NAMESPACE_PREFIX + device


_ENDPOINT = re.compile(r"opc\.tcp://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.\-]{1,253}):([0-9]{1,5})(/[!-~]{0,200})?")


def parse_endpoint(endpoint: str) -> tuple[str, int, str]:
    """``opc.tcp://host:port/path`` as (host, port, path); a ProtocolError says what is wrong with any other."""
    match = _ENDPOINT.fullmatch(endpoint) if isinstance(endpoint, str) else None
    if match is None:
        raise ProtocolError(f"OPC UA endpoint {str(endpoint)[:80]!r} is not opc.tcp://HOST:PORT[/PATH]")
    host, port = match.group(1).strip("[]"), int(match.group(2))
    if not 0 < port < 65536:
        raise ProtocolError(f"OPC UA endpoint {endpoint!r} has no port from 1 to 65535")
    return host, port, match.group(3) or ""


LDS_VARIABLE = "PNP_LDS"
"""Environment variable naming the Local Discovery Server to ask when no ``--lds`` is given."""


def chosen_lds(option: str | None = None) -> str | None:
    """The Local Discovery Server the command line chose (``--lds``, else ``PNP_LDS``, else none), checked to be
    ``opc.tcp://HOST:PORT`` (a ProtocolError, one line, otherwise)."""
    lds = (option or os.environ.get(LDS_VARIABLE, "")).strip() or None
    if lds is not None:
        parse_endpoint(lds)
    return lds


def format_endpoint(host: str, port: int, path: str = "") -> str:
    """The endpoint URL for ``host``, ``port`` and ``path`` (an IPv6 address in brackets)."""
    shown = f"[{host}]" if ":" in host else host
    return f"opc.tcp://{shown}:{port}{path}"


def to_wire(value: Any, kind: Kind, where: str) -> tuple[Any, str]:
    """A controller value as the Python value and the OPC UA built-in type name it travels as.

    A ProtocolError names ``where`` (device, request and argument) when the value does not fit the kind.
    """
    if kind == "any":
        kind = _guess(value)
    if kind == "pose":
        numbers = value.split() if isinstance(value, str) else value
        if not isinstance(numbers, (list, tuple)) or len(numbers) != 6:
            raise ProtocolError(f"{where}: a pose is six numbers (Double[6]); found {str(value)[:80]!r}")
        return [_number(n, where) for n in numbers], "Double"
    if kind == "double":
        return _number(value, where), "Double"
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int) or not -(2**63) <= value < 2**63:
            raise ProtocolError(f"{where}: expected an Int64; found {str(value)[:80]!r}")
        return value, "Int64"
    if kind == "bool":
        if not isinstance(value, bool):
            raise ProtocolError(f"{where}: expected a Boolean; found {str(value)[:80]!r}")
        return value, "Boolean"
    text = str(value)
    if len(text) > MAX_STRING:
        raise ProtocolError(f"{where}: a string of {len(text)} characters; at most {MAX_STRING}")
    return text, "String"


def _guess(value: Any) -> Kind:
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "int"
    if isinstance(value, float):
        return "double"
    if isinstance(value, (list, tuple)) and len(value) == 6:
        return "pose"
    return "string"


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ProtocolError(f"{where}: expected a number (Double); found {str(value)[:80]!r}")
    try:
        number = float(value)
    except ValueError:
        raise ProtocolError(f"{where}: expected a number (Double); found {str(value)[:80]!r}") from None
    if not math.isfinite(number):
        raise ProtocolError(f"{where}: expected a finite number; found {value!r}")
    return number


def from_wire(value: Any, where: str) -> Any:
    """A value read from a device, held to the limits: scalars and flat arrays of the built-in types only."""
    if isinstance(value, (list, tuple)):
        if len(value) > MAX_ARRAY:
            raise ProtocolError(f"{where}: an array of {len(value)} values; at most {MAX_ARRAY}")
        return [_scalar(v, where) for v in value]
    return _scalar(value, where)


def _scalar(value: Any, where: str) -> Any:
    if value is None or isinstance(value, (bool, int)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ProtocolError(f"{where}: {value!r} is no finite number")
        return value
    if isinstance(value, str):
        if len(value) > MAX_STRING:
            raise ProtocolError(f"{where}: a string of {len(value)} characters; at most {MAX_STRING}")
        return value
    raise ProtocolError(f"{where}: a value of type {type(value).__name__}; expected a number, Boolean, "
                        "String or an array of them")
