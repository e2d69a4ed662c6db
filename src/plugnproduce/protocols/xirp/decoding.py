"""Bytes → XIRP messages: hardened parsing, validation against ``xirp.xsd``, then reading.

:func:`decode` parses with the project's hardened parser (no DOCTYPE, no entities,
bounded depth), validates the document against the shipped XSD, and only then
reads it, so every message it returns is valid and typed. Nothing here touches a
socket.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from datetime import UTC, datetime
from functools import lru_cache

from lxml import etree

from plugnproduce.errors import DescriptionError, excerpt, tidy
from plugnproduce.protocols.xirp.messages import (
    ID_PATTERN,
    MALFORMED,
    NAME_PATTERN,
    NAMESPACE,
    Bye,
    Document,
    ErrorMessage,
    Event,
    Failure,
    Hello,
    Message,
    MessageError,
    Pose,
    Request,
    Response,
    Value,
)
from plugnproduce.resources import package_file
from plugnproduce.safeio import parse_xml_bytes, read_bytes

_NS = "{" + NAMESPACE + "}"

MAX_SEQ = 2**63 - 1
"""Largest event sequence number accepted (a device numbers its events from 1)."""


@lru_cache(maxsize=1)
def schema() -> etree.XMLSchema:
    """The XIRP message schema shipped with the package (``xirp.xsd``), loaded once."""
    path = package_file("protocols", "xirp", "xirp.xsd")
    return etree.XMLSchema(parse_xml_bytes(read_bytes(path), path))


_REQUEST_ID = re.compile(rb"<(?:\w+:)?request\b[^>]*?\sid=[\"']([A-Za-z0-9_.\-]{1,64})[\"']")


def _sniffed_id(data: bytes) -> str | None:
    """The id of a request too broken to parse, if one can be read (so the error can name it)."""
    match = _REQUEST_ID.search(data, 0, 1024)
    return match.group(1).decode("ascii") if match else None


_LINE_SUFFIX = re.compile(r",? line \d+\s*$")
_DECLARED_ENCODING = re.compile(rb"""^<\?xml[^>]*?\sencoding\s*=\s*["']([A-Za-z0-9._\-]+)["']""")


# The two commonest messages, a response without results (a command accepted) and a
# request without parameters, are recognised byte for byte in the exact form encode()
# writes them. Each string these expressions match is a well-formed document without
# DOCTYPE, valid against the schema, and decodes to the same message by the full path
# (tests check both); anything else, down to one space more, takes the full path. This
# halves the cost of a command round trip, most of which is parsing and validating.
_NS_BYTES = re.escape(NAMESPACE.encode())
_ID_BYTES = ID_PATTERN.pattern.encode()
_BARE_RESPONSE = re.compile(rb'<response xmlns="' + _NS_BYTES + rb'" id="(' + _ID_BYTES + rb')"/>')
_BARE_REQUEST = re.compile(
    rb'<request xmlns="'
    + _NS_BYTES
    + rb'" id="('
    + _ID_BYTES
    + rb')" name="('
    + NAME_PATTERN.pattern.encode()
    + rb')"/>'
)
_BARE_MAX = 300

# Requests and responses carrying decimals, integers, booleans and poses (every command with
# parameters, most results) are recognised the same way: in the exact form encode() writes them,
# each number in a plain decimal form that is valid for the schema's type and means the same to
# float() and int() as to the full path. Strings (which may need escapes) and documents take the
# full path, and so does a value named twice (the schema refuses it).
_NAME_BYTES = NAME_PATTERN.pattern.encode()
_DECIMAL = rb"-?[0-9]{1,40}(?:\.[0-9]{1,40})?"
_TYPED_VALUE = (rb'<(?:decimal name="' + _NAME_BYTES + rb'">' + _DECIMAL + rb"</decimal>"
                rb'|integer name="' + _NAME_BYTES + rb'">-?[0-9]{1,18}</integer>'
                rb'|boolean name="' + _NAME_BYTES + rb'">(?:true|false)</boolean>'
                rb'|pose name="' + _NAME_BYTES + rb'">' + _DECIMAL + rb"(?: " + _DECIMAL + rb"){5}</pose>)")
_TYPED_REQUEST = re.compile(rb'<request xmlns="' + _NS_BYTES + rb'" id="(' + _ID_BYTES + rb')" name="('
                            + _NAME_BYTES + rb')">((?:' + _TYPED_VALUE + rb")+)</request>")
_TYPED_RESPONSE = re.compile(rb'<response xmlns="' + _NS_BYTES + rb'" id="(' + _ID_BYTES + rb')">((?:'
                             + _TYPED_VALUE + rb")+)</response>")
_ONE_VALUE = re.compile(rb'<([a-z]+) name="([^"]+)">([^<]*)<')
_TYPED_MAX = 4096


def _typed_values(content: bytes) -> dict[str, Value] | None:
    """The values of content :data:`_TYPED_VALUE` matched; None when a name comes twice."""
    values: dict[str, Value] = {}
    for tag, name, text in _ONE_VALUE.findall(content):
        key = name.decode("ascii")
        if key in values:
            return None
        values[key] = _VALUE_READERS[_NS + tag.decode("ascii")](text.decode("ascii"))
    return values


def _typed(data: bytes) -> Message | None:
    match = _TYPED_REQUEST.fullmatch(data)
    if match is not None:
        values = _typed_values(match.group(3))
        return None if values is None else Request(match.group(1).decode("ascii"), match.group(2).decode("ascii"),
                                                   values)
    match = _TYPED_RESPONSE.fullmatch(data)
    if match is not None:
        values = _typed_values(match.group(2))
        return None if values is None else Response(match.group(1).decode("ascii"), values)
    return None


def _bare(data: bytes) -> Message | None:
    match = _BARE_RESPONSE.fullmatch(data)
    if match is not None:
        return Response(match.group(1).decode("ascii"))
    match = _BARE_REQUEST.fullmatch(data)
    if match is not None:
        return Request(match.group(1).decode("ascii"), match.group(2).decode("ascii"), {})
    return None


def decode(data: bytes, source: str = "peer") -> Message:
    """Read one message; :class:`MessageError` (``malformed``) says what is wrong and where.

    ``source`` names the sender in messages (``"message from 127.0.0.1:50312"``).
    """
    if len(data) <= _BARE_MAX:
        bare = _bare(data)
        if bare is not None:
            return bare
    if len(data) <= _TYPED_MAX:
        try:
            typed = _typed(data)
        except MessageError:  # a number too large: the full path says so in its words
            typed = None
        if typed is not None:
            return typed
    return _decode_document(data, source)


def _decode_document(data: bytes, source: str) -> Message:
    """The full path: hardened parse, schema validation, then reading."""
    try:
        tree = parse_xml_bytes(data, source)
    except DescriptionError as exc:
        raise MessageError(f"{source}: {exc.message}", MALFORMED, _sniffed_id(data)) from exc
    if data[:5] == b"<?xml":
        declared = _DECLARED_ENCODING.match(data)
        if declared is not None and declared.group(1).upper() not in (b"UTF-8", b"UTF8"):
            encoding = declared.group(1).decode("ascii")
            raise MessageError(f"{source}: declared encoding {encoding}; expected UTF-8", MALFORMED, _sniffed_id(data))
    root = tree.getroot()
    try:
        schema().assertValid(root)
    except etree.DocumentInvalid as exc:
        reason = str(exc).replace(_NS, "").replace(_NS[1:-1], "xirp")
        reason = tidy(_LINE_SUFFIX.sub("", reason))  # a message is one document: its line says nothing
        ref = root.get("id") if root.tag == _NS + "request" else None
        ref = ref if ref is not None and ID_PATTERN.fullmatch(ref) else None
        raise MessageError(f"{source}: not a valid XIRP message: {reason}", MALFORMED, ref) from exc
    try:
        return _DECODERS[root.tag](root)  # the schema admits only these roots
    except MessageError as exc:
        raise MessageError(f"{source}: {exc}", MALFORMED, exc.ref) from None


def _content(el: etree._Element) -> str:
    """The element's text, even when comments or processing instructions split it."""
    if len(el):
        return "".join(el.itertext())
    return el.text or ""


def _number(text: str) -> float:
    number = float(text)
    if not math.isfinite(number):
        raise MessageError(f"decimal {text.strip()[:40]!r} is too large for a number", MALFORMED)
    return number


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError as exc:  # more digits than Python converts
        raise MessageError(f"integer of {len(text.strip())} digits is too long", MALFORMED) from exc


def _boolean(text: str) -> bool:
    return text.strip() in ("true", "1")


def _string(text: str) -> str:
    return text


def _pose(text: str) -> Pose:
    numbers = list(map(float, text.split()))
    if not all(map(math.isfinite, numbers)):
        raise MessageError(f"pose {text.strip()[:80]!r} holds a number too large", MALFORMED)
    return Pose._make(numbers)


_VALUE_READERS: dict[str, Callable[[str], Value]] = {
    _NS + "decimal": _number,
    _NS + "integer": _integer,
    _NS + "boolean": _boolean,
    _NS + "string": _string,
    _NS + "pose": _pose,
}


def _read_values(el: etree._Element) -> dict[str, Value]:
    values: dict[str, Value] = {}
    for child in el:
        reader = _VALUE_READERS.get(child.tag)
        if reader is not None:
            text = "".join(child.itertext()) if len(child) else child.text  # comments may split the text
            values[child.get("name")] = reader(text or "")
    return values


def _decode_hello(el: etree._Element) -> Hello:
    version = _integer(el.get("version"))
    return Hello(el.get("device"), el.get("class"), el.get("label"), el.get("describe"), version)


def _decode_request(el: etree._Element) -> Request:
    try:
        return Request(el.get("id"), el.get("name"), _read_values(el) if len(el) else {})
    except MessageError as exc:
        raise MessageError(f"request {el.get('id')}: {exc}", MALFORMED, el.get("id")) from None


def _decode_response(el: etree._Element) -> Response:
    if not len(el):
        return Response(el.get("id"))
    failure = el.find(_NS + "failure")
    if failure is not None:
        return Response(el.get("id"), failure=Failure(failure.get("code"), _content(failure)))
    documents = tuple(
        Document(d.get("name"), d.get("media-type"), _content(d)) for d in el.iterchildren(_NS + "document")
    )
    return Response(el.get("id"), _read_values(el), documents)


def _decode_event(el: etree._Element) -> Event:
    text = el.get("time").strip()
    try:
        time = datetime.fromisoformat(text)
    except ValueError as exc:  # xs:dateTime admits a few forms Python does not (24:00:00, year 0)
        raise MessageError(f"event time {excerpt(text)!r} cannot be read ({tidy(str(exc))})", MALFORMED) from exc
    if time.tzinfo is None:
        time = time.replace(tzinfo=UTC)
    seq = _integer(el.get("seq"))
    if seq > MAX_SEQ:
        raise MessageError(f"event sequence number of {len(str(seq))} digits is larger than {MAX_SEQ}", MALFORMED)
    return Event(el.get("name"), seq, time, _read_values(el) if len(el) else {})


def _decode_error(el: etree._Element) -> ErrorMessage:
    return ErrorMessage(el.get("code"), _content(el), el.get("ref"))


def _decode_bye(el: etree._Element) -> Bye:
    return Bye(el.get("reason"))


_DECODERS: dict[str, Callable[[etree._Element], Message]] = {
    _NS + "hello": _decode_hello,
    _NS + "request": _decode_request,
    _NS + "response": _decode_response,
    _NS + "event": _decode_event,
    _NS + "error": _decode_error,
    _NS + "bye": _decode_bye,
}
