"""What "within contract" means: one value against one argument contract of a device request.

The one definition every stage uses. The plausibility check holds a task's values to it before a
program is made, verification holds the program's arguments to it, and the executor's run-time
monitor holds every argument to it immediately before a request goes out, whatever the value's
source: a literal, a default, an earlier step's output, or a value that changes from one loop
iteration to the next.

A contract (``pnp:RequestArgument``) names the argument's datatype, unit, minimum, maximum and,
for a pose, the device's reach (``pnp:maxReach``, from its base in the length of the contract's pose unit,
metres if it names none). A value is judged in the unit it is given in and converted to the contract's unit
first; a pose per component (x, y, z by the length unit, rx, ry, rz by the angle unit).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from plugnproduce.description.model import Argument
from plugnproduce.description.quantities.kinds import KINDS as KINDS
from plugnproduce.description.quantities.kinds import XSD as XSD
from plugnproduce.description.quantities.kinds import kind_of as kind_of
from plugnproduce.description.quantities.units import UnitError, convert, convert_pose, pose_units
from plugnproduce.ontology.iris import local_name

MAX_STRING = 1024
"""The longest text a request argument may carry (a part type, a program name)."""
MAX_ITEMS = 64
"""The most items a list argument may carry."""
POSE_SIZE = 6
"""A pose is x, y, z (m) and rx, ry, rz (deg)."""


def breach(value: object, unit: str, contract: Argument, *, types: bool = True) -> str | None:
    """Why ``value`` (given in ``unit``) breaks ``contract``, or None if the device takes it.

    With ``types`` the value's datatype and size are judged too (the plausibility check tells of a
    wrong type by the process's own parameter, so it judges only limits and reach).
    """
    if types:
        wrong = _type_breach(value, kind_of(contract.datatype))
        if wrong is not None:
            return wrong
    position = pose_position(value)
    if position is not None:
        why = _pose_breach(position, unit, contract)
        if why is not None:
            return why
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return _limit_breach(value, unit, contract, whole=types and kind_of(contract.datatype) == "integer")


def _pose_breach(position: tuple[float, float, float], unit: str, contract: Argument) -> str | None:
    """Why a pose at ``position`` (in the pose unit ``unit``) is beyond the reach, in the contract's unit."""
    try:
        x, y, z = convert_pose([*position, 0.0, 0.0, 0.0], unit, contract.unit)[:3]
    except UnitError as exc:
        return f"takes a pose in {contract.unit}; the value is given in {unit} ({exc})"
    units = pose_units(contract.unit)
    length = units[0] if units is not None else "m"
    distance = math.dist((x, y, z), (0.0, 0.0, 0.0))
    if contract.reach is not None and distance > contract.reach:
        return (f"reaches at most {contract.reach:g} {length} from its base; "
                f"the pose is {_shown(distance)} {length} away")
    return None


def _shown(distance: float) -> str:
    """A distance to three figures, never in an exponent (2000 mm, not 2e+03 mm)."""
    return f"{distance:.3g}" if distance < 1000 else f"{distance:.0f}"


def _limit_breach(value: float, unit: str, contract: Argument, *, whole: bool = False) -> str | None:
    """Why ``value`` (in ``unit``) is beyond the contract's limits, judged in the contract's unit; with ``whole``,
    also a number that is whole only before its conversion (45 N is 4.5 daN)."""
    try:
        number = convert(float(value), unit, contract.unit)
    except UnitError as exc:
        return (f"takes {local_name(contract.quantity)} in {contract.unit}; the value is given in "
                f"{unit or 'no unit'} ({exc})")
    if not math.isfinite(number):
        return f"takes a finite number; the value is {value!r}"
    shown_unit = f" {contract.unit}" if contract.unit else ""
    shown = f"{value:g} {unit}".strip() if unit != contract.unit else f"{number:g}{shown_unit}"
    if whole and not number.is_integer():
        return f"takes a whole number of {contract.unit}; the value is {shown} ({number:g} {contract.unit})"
    if contract.minimum is not None and number < contract.minimum:
        return f"takes at least {contract.minimum:g}{shown_unit}; the value is {shown}"
    if contract.maximum is not None and number > contract.maximum:
        return f"takes at most {contract.maximum:g}{shown_unit}; the value is {shown}"
    return None


def _type_breach(value: object, kind: str) -> str | None:
    """Why ``value`` is no value of ``kind``, or of any reasonable size; None if it is."""
    size = _size_breach(value)
    if size is not None:
        return size
    if kind == "pose" and (pose_position(value) is None or not _all_finite(_items(value))):
        return f"takes a pose of {POSE_SIZE} finite numbers; the value is {shorten(value)}"
    if kind in ("decimal", "integer") and (isinstance(value, bool) or not isinstance(value, int | float)):
        return f"takes a number; the value is {shorten(value)}"
    if kind == "integer" and isinstance(value, float) and not value.is_integer():
        return f"takes a whole number; the value is {value!r}"
    if kind == "boolean" and not isinstance(value, bool):
        return f"takes true or false; the value is {shorten(value)}"
    if kind == "string" and not isinstance(value, str):
        return f"takes a text; the value is {shorten(value)}"
    if isinstance(value, float) and not math.isfinite(value):
        return f"takes a finite number; the value is {value!r}"
    return None


def _size_breach(value: object) -> str | None:
    if isinstance(value, str) and len(value) > MAX_STRING:
        return f"takes at most {MAX_STRING} characters; the value has {len(value):,}"
    if isinstance(value, list | tuple):
        if len(value) > MAX_ITEMS:
            return f"takes at most {MAX_ITEMS} items; the value has {len(value):,}"
        if not all(isinstance(v, int | float | str) and not isinstance(v, bool) and _size_breach(v) is None
                   for v in value):
            return f"takes a list of numbers; the value is {shorten(value)}"
    elif isinstance(value, Mapping):
        return f"takes no mapping; the value is {shorten(value)}"
    elif value is not None and not isinstance(value, str | int | float | bool):
        return f"takes no {type(value).__name__}; the value is {shorten(value)}"
    return None


def _items(value: object) -> list[Any]:
    items = value.split() if isinstance(value, str) else value
    return list(items) if isinstance(items, list | tuple) else []


def _all_finite(items: list[Any]) -> bool:
    try:
        return all(math.isfinite(float(v)) for v in items)
    except (TypeError, ValueError, OverflowError):
        return False


def pose_position(value: object) -> tuple[float, float, float] | None:
    """The x, y, z of a pose written as a list or as six numbers in a string (None: no pose)."""
    if isinstance(value, str) and len(value) > MAX_STRING:
        return None
    items = _items(value)
    if len(items) != POSE_SIZE or any(isinstance(v, bool) for v in items):
        return None
    try:
        x, y, z = (float(v) for v in items[:3])
    except (TypeError, ValueError, OverflowError):
        return None
    return (x, y, z) if all(math.isfinite(v) for v in (x, y, z)) else None


def shorten(value: object, limit: int = 60) -> str:
    """A value as a message shows it: its repr, cut to ``limit`` characters with its length told."""
    text = repr(value)
    if len(text) <= limit:
        return text
    size = f"{len(value):,} characters" if isinstance(value, str) else f"{len(text):,} characters written"
    return f"{text[:limit]}… ({size})"


def pose_items(value: object) -> list[float] | None:
    """A pose written as a list or as six numbers in a string, as six floats (None: no pose)."""
    if pose_position(value) is None:
        return None
    try:
        items = [float(v) for v in _items(value)]
    except (TypeError, ValueError, OverflowError):
        return None
    return items if all(math.isfinite(v) for v in items) else None



def in_unit(value: object, unit: str, to: str) -> object:
    """A number or a pose in ``unit`` converted to ``to`` (a pose per component, :func:`convert_pose`); anything
    else as it is. What cannot be converted raises: it never goes out as it is."""
    if not unit or not to or unit == to:
        return value
    pose = pose_items(value)
    if pose is not None:
        return convert_pose(pose, unit, to)
    if isinstance(value, bool) or not isinstance(value, int | float):
        return value
    return convert(float(value), unit, to)


def in_contract_unit(value: object, unit: str, contract: Argument) -> object:
    """A value in ``unit`` as it goes to ``contract``'s argument: in the argument's unit (:func:`in_unit`), and a
    whole number written as one where the argument takes whole numbers (40 N as 4 daN, not 4.0)."""
    out = in_unit(value, unit, contract.unit)
    if kind_of(contract.datatype) == "integer" and isinstance(out, float) and out.is_integer():
        return int(out)
    return out
