"""Argument values on the wire: the lexical form of each datatype a request argument can have.

Chart-derived actions take every argument as a UPnP ``string``; what the string holds is
the XML Schema lexical form of the argument's datatype (``docs/upnp.md``, "Argument values
on the wire"). :func:`lexical` writes a value so (the controller's side); :func:`parse_lexical`
reads it back as strictly as the datatype says (the device's side), refusing anything else.
"""

from __future__ import annotations

import math
import re
from decimal import Decimal
from typing import Any

POSE_ITEMS = 6
"""A pose is x y z (m) and rx ry rz (deg)."""

_DECIMAL = re.compile(r"^[+-]?(?:\d+(?:\.\d*)?|\.\d+)$")
_INTEGER = re.compile(r"^[+-]?\d+$")
_BOOLEAN = {"true": True, "1": True, "false": False, "0": False}
MAX_TEXT = 1024
"""Longest argument text read; a longer one is refused unread."""


def lexical(value: Any) -> str:
    """A value in its lexical form: a number in plain decimal notation (``40``, ``0.5``, ``0.00001``, never an
    exponent), a boolean ``true``/``false``, a pose or other sequence its items separated by one space, a
    string as it is."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"{value!r} has no lexical form: a decimal is finite")
        return format(Decimal(repr(value)), "f")
    if isinstance(value, list | tuple):
        return " ".join(lexical(v) for v in value)
    return str(value)


def parse_lexical(text: str, datatype: str) -> Any:
    """The value ``text`` stands for in ``datatype`` (a local name: ``decimal``, ``integer``, ``boolean``,
    ``string``, ``Pose``; ``""`` for an argument of no declared type, taken as it is). ValueError saying what
    was expected if the text is not that datatype's lexical form."""
    if len(text) > MAX_TEXT:
        raise ValueError(f"{len(text)} characters; at most {MAX_TEXT} are read")
    if datatype == "decimal":
        return _number(text, _DECIMAL, "a decimal such as 40 or 0.5")
    if datatype == "integer":
        _number(text, _INTEGER, "an integer such as 3")
        return int(text)
    if datatype == "boolean":
        if text not in _BOOLEAN:
            raise ValueError(f"{text[:40]!r} is not a boolean; expected true, false, 1 or 0")
        return _BOOLEAN[text]
    if datatype == "Pose":
        items = text.split(" ")
        if len(items) != POSE_ITEMS or not all(_DECIMAL.match(i) for i in items):
            raise ValueError(f"{text[:60]!r} is not a pose; expected six decimals separated by one space, "
                             "x y z rx ry rz")
        return [float(i) for i in items]
    return text


def _number(text: str, form: re.Pattern[str], expected: str) -> float:
    if not form.match(text):
        raise ValueError(f"{text[:40]!r} is not {expected}")
    return float(text)
