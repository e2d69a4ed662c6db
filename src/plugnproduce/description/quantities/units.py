"""Quantities with real units (pint): how a value a task writes is read and converted.

A task writes a quantity as a number (in the parameter's declared unit) or as a string of a
number and a unit, ``"120 N"`` or ``"0.12 kN"``; both name the same force. A device's contract
may declare another unit than the process parameter (``mm/s`` against ``m/s``): values are
converted, and a value in a unit of another dimension (``12 kg`` for a force) is refused.
"""

from __future__ import annotations

import math
import re
from functools import cache
from typing import TYPE_CHECKING

from plugnproduce.deferred import dataclass
from plugnproduce.description.quantities.unitcache import Incompatible, UnitTable, table_file
from plugnproduce.errors import PlugNProduceError
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    import pint
else:  # pint is imported only when a unit is new to the cached table (unitcache.py), or for its error classes
    pint = lazy_module("pint")

MAX_TEXT = 64
"""Longest quantity text read; a longer string is no quantity."""

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d{1,3})?|[-+]?(?:nan|inf|infinity))\s*"
                       r"([A-Za-z%°µΩ].*)?$", re.IGNORECASE | re.ASCII)
"""A number in ASCII digits only (``float`` would also read ``"١٢٠"`` and ``"𝟒𝟓"``), then its unit."""
_FACTOR = r"[A-Za-z%°µΩ_]+(?:(?:\*\*|\^)-?\d{1,2})?"
_UNIT = re.compile(rf"^{_FACTOR}(?:\s*[*/· ]\s*{_FACTOR})*$")
"""Units as factors with small whole exponents (``N m``, ``mm/s``, ``m/s^2``): nothing pint would compute long on."""


class UnitError(PlugNProduceError, ValueError):
    """A unit the registry does not know, or a conversion between different dimensions."""


@dataclass(frozen=True)
class Amount:
    """A number and the unit it is in (``""``: the parameter's own unit)."""

    number: float
    unit: str


@cache
def registry() -> UnitTable:
    """The one unit registry: pint's answers kept in the user's cache folder (:mod:`.unitcache`), read on first
    use; pint itself is built only for a unit no earlier process has asked of."""
    return UnitTable(table_file())


def read_amount(value: object) -> Amount | None:
    """A value as a number with an optional unit; None if it is neither (a pose, a word, a boolean)."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        return Amount(float(value), "")
    if not isinstance(value, str) or len(value) > MAX_TEXT:
        return None
    m = _QUANTITY.match(value)
    if m is None:
        return None
    return Amount(float(m.group(1)), (m.group(2) or "").strip())


def unit_known(unit: str) -> bool:
    """Whether ``unit`` is a unit the registry can read (``""`` is: it means none)."""
    if not unit:
        return True
    if len(unit) > MAX_TEXT or not _UNIT.match(unit):
        return False
    try:
        registry().Unit(_spelling(unit))
    except (pint.PintError, AttributeError, ValueError, TypeError, SyntaxError, ArithmeticError):  # pint on bad text
        return False
    return True


def convert(number: float, unit: str, to: str) -> float:
    """``number`` in ``unit`` expressed in ``to``; the same number when either is ``""``.

    Raises :class:`UnitError` for an unknown unit or units of different dimensions.
    """
    if not unit or not to or unit == to or not math.isfinite(number):
        return number
    for u in (unit, to):
        if not unit_known(u):
            raise UnitError(f"unknown unit {u!r}")
    ureg = registry()
    try:
        return float(ureg.Quantity(number, _spelling(unit)).to(_spelling(to)).magnitude)
    except Incompatible as exc:  # remembered by the table: no need to load pint for its error classes
        raise UnitError(f"{unit} cannot be converted to {to}") from exc
    except (pint.PintError, AttributeError, ValueError, TypeError, ArithmeticError) as exc:  # pint's own and offsets
        raise UnitError(f"{unit} cannot be converted to {to}") from exc


def number_in(value: str, unit: str) -> float | None:
    """A quantity written as text (``"0.12 kN"``) as a number in ``unit``; None if it is none, is not
    finite (as written or in ``unit``), or cannot be converted (the check says which)."""
    amount = read_amount(value)
    if amount is None or not math.isfinite(amount.number) or (amount.unit and not unit):
        return None
    try:
        number = convert(amount.number, amount.unit, unit)
    except UnitError:
        return None
    return number if math.isfinite(number) else None  # 1e308 kN is no number in N


def _spelling(unit: str) -> str:
    """How pint reads a unit written in a description (``%`` is ``percent``)."""
    return unit.replace("%", "percent")


def pose_units(unit: str) -> tuple[str, str] | None:
    """A pose unit ``"LENGTH ANGLE"`` (``"m deg"``, ``"mm rad"``) as its two units; None if it is none."""
    parts = unit.split()
    if len(parts) != 2 or not all(unit_known(p) for p in parts):
        return None
    try:
        convert(1.0, parts[0], "m")
        convert(1.0, parts[1], "deg")
    except UnitError:
        return None
    return parts[0], parts[1]


def convert_pose(pose: list[float], unit: str, to: str) -> list[float]:
    """A pose (x, y, z, rx, ry, rz) in the pose unit ``unit`` expressed in ``to``: x, y, z by the length
    units, rx, ry, rz by the angle units; the same pose when either is ``""`` or both are the same.

    Raises :class:`UnitError` if either is no pose unit (a refusal is better than a wrong conversion).
    """
    if not unit or not to or unit == to:
        return pose
    given, wanted = pose_units(unit), pose_units(to)
    if given is None or wanted is None:
        bad = unit if given is None else to
        raise UnitError(f"{bad!r} is no pose unit; expected a length and an angle such as \"m deg\"")
    return ([convert(float(v), given[0], wanted[0]) for v in pose[:3]]
            + [convert(float(v), given[1], wanted[1]) for v in pose[3:]])


def reach_length(unit: str) -> str:
    """The length unit a reach is given in for a pose in ``unit``: its first part, metres for ``""``."""
    if not unit:
        return "m"
    units = pose_units(unit)
    if units is None:
        raise UnitError(f"{unit!r} is no pose unit; expected a length and an angle such as \"m deg\"")
    return units[0]


def no_pose_unit(unit: str) -> str | None:
    """Why ``unit`` declared for a pose is no pose unit (``""`` is one: the pose as it is), or None."""
    if not unit or pose_units(unit) is not None:
        return None
    return f"{unit[:MAX_TEXT]!r} is no pose unit; expected a length and an angle such as \"m deg\" or \"mm rad\""
