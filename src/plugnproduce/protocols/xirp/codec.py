"""XIRP messages → bytes: framing and encoding (the way back is :mod:`~plugnproduce.protocols.xirp.decoding`).

A frame is a 4-byte big-endian length followed by that many bytes: one UTF-8 XML
document, one message. :func:`encode` writes the XML with string formatting (every
name is checked against its pattern, every text escaped, so the output is valid
against the schema). Nothing here touches a socket.
"""

from __future__ import annotations

import math
import re
import struct
from collections.abc import Callable, Mapping
from datetime import datetime
from decimal import Decimal
from typing import Any

from plugnproduce.protocols.files import FILE_NAME_PATTERN
from plugnproduce.protocols.xirp.messages import (
    CODE_PATTERN,
    ID_PATTERN,
    INVALID_VALUE,
    NAME_PATTERN,
    NAMESPACE,
    Bye,
    ErrorMessage,
    Event,
    Hello,
    Message,
    MessageError,
    Pose,
    Request,
    Response,
    Value,
)

HEADER = struct.Struct(">I")
"""The frame header: the length of the XML document that follows, 4 bytes, big-endian."""

MAX_FRAME = 64 * 1024
"""Default largest document accepted in one frame, in bytes (the header not counted)."""

_NS = "{" + NAMESPACE + "}"
_XMLNS = f' xmlns="{NAMESPACE}"'

# ---------------------------------------------------------------- framing


def frame(payload: bytes) -> bytes:
    """Prefix one encoded message with its length."""
    return HEADER.pack(len(payload)) + payload


def frame_length(header: bytes) -> int:
    """The document length a 4-byte header announces."""
    return int(HEADER.unpack(header)[0])


def encode_frame(message: Message) -> bytes:
    """Encode a message and frame it: what goes on the wire."""
    return frame(encode(message))


# ---------------------------------------------------------------- encoding

_ATTENTION = re.compile('[&<>"\r\n\t\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]')
_ILLEGAL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
# Carriage returns (and, in attributes, tabs and newlines) are written as character
# references: an XML parser would otherwise normalise them and the text would not survive.
_TEXT_ESCAPES = str.maketrans({"&": "&amp;", "<": "&lt;", ">": "&gt;", "\r": "&#13;"})
_ATTR_ESCAPES = str.maketrans(
    {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "\r": "&#13;", "\n": "&#10;", "\t": "&#9;"}
)


def _escaped(text: str, table: dict[int, str]) -> str:
    if _ATTENTION.search(text) is None:
        return text
    bad = _ILLEGAL.search(text)
    if bad is not None:
        raise MessageError(f"holds the character U+{ord(bad.group()):04X}, which XML 1.0 cannot carry", INVALID_VALUE)
    return text.translate(table)


def _text(text: str) -> str:
    return _escaped(text, _TEXT_ESCAPES)


def _attr(text: object, label: str) -> str:
    if not isinstance(text, str):
        raise MessageError(f"{label} {text!r} is not a string", INVALID_VALUE)
    try:
        return _escaped(text, _ATTR_ESCAPES)
    except MessageError as exc:
        raise MessageError(f"{label} {exc}", INVALID_VALUE) from None


_NAME_RULE = "letters, digits, '_', '.', '-' (1-128, not starting with a digit)"
_ID_RULE = "1-64 letters, digits, '_', '.', '-'"
_CODE_RULE = "lower-case letters, digits and '-' (1-64, starting with a letter)"
_NAMES: set[str] = set()  # names already checked: the same few request and parameter names recur
_NAMES_LIMIT = 4096


def _checked(pattern: re.Pattern[str], value: object, label: str, rule: str) -> str:
    if not isinstance(value, str) or pattern.fullmatch(value) is None:
        raise MessageError(f"{label} {value!r} is refused; expected {rule}", INVALID_VALUE)
    return value


def _name(value: object, label: str) -> str:
    if value.__class__ is str and value in _NAMES:
        return value
    name = _checked(NAME_PATTERN, value, label, _NAME_RULE)
    if len(_NAMES) < _NAMES_LIMIT:
        _NAMES.add(name)
    return name


def _decimal(value: object) -> str:
    if value.__class__ is float and math.isfinite(value):
        text = repr(value)
        return text if "e" not in text else format(Decimal(text), "f")
    if isinstance(value, float) and math.isfinite(value):
        return _decimal(float(value))
    if isinstance(value, Decimal) and value.is_finite():
        return format(value, "f")
    if isinstance(value, int) and not isinstance(value, bool):
        return format(value, "d")
    raise MessageError(f"{value!r} is not a finite number", INVALID_VALUE)


def _write_decimal(name: str, value: Any) -> str:
    return f'<decimal name="{name}">{_decimal(value)}</decimal>'


def _write_integer(name: str, value: Any) -> str:
    return f'<integer name="{name}">{value:d}</integer>'


def _write_boolean(name: str, value: Any) -> str:
    return f'<boolean name="{name}">{"true" if value else "false"}</boolean>'


def _write_string(name: str, value: Any) -> str:
    return f'<string name="{name}">{_text(value)}</string>'


def _write_pose(name: str, value: Any) -> str:
    if len(value) != 6:
        raise MessageError(f"a pose has six numbers (x y z rx ry rz); got {len(value)}", INVALID_VALUE)
    if value.__class__ is Pose and all(v.__class__ is float for v in value):
        text = " ".join(map(repr, value))
        if "e" not in text and "n" not in text:  # no exponent, no inf, no nan
            return f'<pose name="{name}">{text}</pose>'
    return f'<pose name="{name}">{" ".join([_decimal(v) for v in value])}</pose>'


_WRITERS: dict[type, Callable[[str, Any], str]] = {
    float: _write_decimal,
    Decimal: _write_decimal,
    int: _write_integer,
    bool: _write_boolean,
    str: _write_string,
    Pose: _write_pose,
    tuple: _write_pose,
    list: _write_pose,
}
_KINDS = (bool, int, float, Decimal, str, tuple, list)  # subclasses: bool before int


def _value(name: str, value: object) -> str:
    _name(name, "parameter name")
    writer = _WRITERS.get(value.__class__)
    if writer is None:
        kind = next((k for k in _KINDS if isinstance(value, k)), None)
        writer = _WRITERS[kind] if kind is not None else None
    if writer is None:
        raise MessageError(
            f"parameter {name!r}: {value!r} cannot be sent; expected a decimal, integer, boolean, string or "
            "pose (six numbers)",
            INVALID_VALUE,
        )
    try:
        return writer(name, value)
    except MessageError as exc:
        raise MessageError(f"parameter {name!r}: {exc}", INVALID_VALUE) from None


def _values(params: Mapping[str, Value]) -> str:
    return "".join([_value(name, value) for name, value in params.items()])


def _element(tag: str, attributes: str, content: str) -> str:
    if content:
        return f"<{tag}{_XMLNS}{attributes}>{content}</{tag}>"
    return f"<{tag}{_XMLNS}{attributes}/>"


def _positive(value: object, label: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value < 1:
        raise MessageError(f"{label} {value!r} is refused; expected a positive integer", INVALID_VALUE)
    return value


def _encode_hello(m: Hello) -> str:
    attrs = f' version="{_positive(m.version, "version"):d}" device="{_name(m.device, "device id")}"'
    attrs += f' class="{_attr(m.device_class, "device class")}"'
    if m.label is not None:
        attrs += f' label="{_attr(m.label, "label")}"'
    if m.describe is not None:
        attrs += f' describe="{_name(m.describe, "describe request")}"'
    return _element("hello", attrs, "")


def _encode_request(m: Request) -> str:
    attrs = f' id="{_checked(ID_PATTERN, m.id, "id", _ID_RULE)}" name="{_name(m.name, "name")}"'
    return _element("request", attrs, _values(m.params))


def _encode_response(m: Response) -> str:
    attrs = f' id="{_checked(ID_PATTERN, m.id, "id", _ID_RULE)}"'
    if m.failure is not None:
        if m.results or m.documents:
            raise MessageError("a failure cannot carry results or documents", INVALID_VALUE)
        code = _checked(CODE_PATTERN, m.failure.code, "failure code", _CODE_RULE)
        return _element("response", attrs, f'<failure code="{code}">{_text(m.failure.text)}</failure>')
    content = _values(m.results)
    for d in m.documents:
        name = _checked(FILE_NAME_PATTERN, d.name, "document name", "a plain file name")
        media = _attr(d.media_type, "media type")
        content += f'<document name="{name}" media-type="{media}">{_text(d.text)}</document>'
    return _element("response", attrs, content)


def _encode_event(m: Event) -> str:
    if not isinstance(m.time, datetime) or m.time.tzinfo is None:
        raise MessageError(f"time {m.time!r} is refused; expected an aware (UTC) datetime", INVALID_VALUE)
    seq = _positive(m.seq, "sequence number")
    attrs = f' name="{_name(m.name, "name")}" seq="{seq:d}" time="{m.time.isoformat()}"'
    return _element("event", attrs, _values(m.params))


def _encode_error(m: ErrorMessage) -> str:
    attrs = f' code="{_checked(CODE_PATTERN, m.code, "code", _CODE_RULE)}"'
    if m.ref is not None:
        attrs += f' ref="{_checked(ID_PATTERN, m.ref, "ref", _ID_RULE)}"'
    return _element("error", attrs, _text(m.text))


def _encode_bye(m: Bye) -> str:
    return _element("bye", "" if m.reason is None else f' reason="{_attr(m.reason, "reason")}"', "")


_ENCODERS: dict[type, Callable[[Any], str]] = {
    Hello: _encode_hello,
    Request: _encode_request,
    Response: _encode_response,
    Event: _encode_event,
    ErrorMessage: _encode_error,
    Bye: _encode_bye,
}


def _label(message: Message) -> str:
    """How a message is named in an error: ``request 'MoveTo'``, ``response to '7'``, ``hello``."""
    if isinstance(message, Request | Event):
        return f"{type(message).__name__.lower()} {message.name!r}"
    if isinstance(message, Response):
        return f"response to {message.id!r}"
    return "error" if isinstance(message, ErrorMessage) else type(message).__name__.lower()


def encode(message: Message) -> bytes:
    """One message as a UTF-8 XML document; :class:`MessageError` (``invalid-value``) if it cannot be sent."""
    encoder = _ENCODERS.get(type(message))
    if encoder is None:
        raise MessageError(f"{message!r} is not an XIRP message", INVALID_VALUE)
    try:
        return encoder(message).encode()
    except MessageError as exc:
        raise MessageError(f"{_label(message)}: {exc}", INVALID_VALUE) from None
    except (TypeError, ValueError) as exc:  # a field of the wrong type, e.g. text that is not a string
        raise MessageError(f"{_label(message)}: cannot be encoded ({exc})", INVALID_VALUE) from exc
