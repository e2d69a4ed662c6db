"""The edits of a repair, typed: the terms repair.lp shows inside ``edit/1``, decoded in one place.

``I`` is an original step of the task (of the window, for window.lp), ``J`` an insertion slot before it,
``P`` a process command, ``R`` a role, ``D`` and ``A`` devices, ``N`` a parameter. A term of no kind below
is an error of the encodings, said as such.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar, Self

import clingo

from plugnproduce.errors import EncodingError
from plugnproduce.reasoning.asp.terms import quote


@dataclass(frozen=True)
class StepEdit:
    """An edit of original step ``i``."""

    kind: ClassVar[str]
    i: int

    def shifted(self, offset: int) -> Self:
        """The same edit of the step ``offset`` further on (a window's step as the whole task's)."""
        return dataclasses.replace(self, i=self.i + offset) if offset else self


@dataclass(frozen=True)
class Insert(StepEdit):
    """``insert(I,J,P)``: process ``p`` inserted in the ``j``-th slot before step ``i``."""

    kind = "insert"
    j: int
    p: str


@dataclass(frozen=True)
class Remove(StepEdit):
    """``remove(I)``: step ``i`` removed."""

    kind = "remove"


@dataclass(frozen=True)
class Swap(StepEdit):
    """``swap(I)``: step ``i`` swapped with the next."""

    kind = "swap"


@dataclass(frozen=True)
class Rebind(StepEdit):
    """``rebind(I,R,D)``: role ``r`` of step ``i`` bound to device ``d`` instead of the one written."""

    kind = "rebind"
    r: str
    d: str


@dataclass(frozen=True)
class Bind(StepEdit):
    """``bind(I,R,D)``: role ``r`` of step ``i``, unbound and with several devices fitting, bound to ``d``."""

    kind = "bind"
    r: str
    d: str


@dataclass(frozen=True)
class Unbind(StepEdit):
    """``unbind(I,R)``: the binding of ``r``, no role of step ``i``'s command, dropped."""

    kind = "unbind"
    r: str


@dataclass(frozen=True)
class Reset(StepEdit):
    """``reset(I,N)``: parameter ``n`` of step ``i`` reset to its default (or dropped when undeclared)."""

    kind = "reset"
    n: str


@dataclass(frozen=True)
class Add:
    """``add(A)``: device ``a`` of the catalogue added to the cell."""

    kind: ClassVar[str] = "add"
    a: str

    def shifted(self, offset: int) -> Self:
        """The same edit: adding a device concerns no step."""
        return self


EditTerm = Insert | Remove | Swap | Rebind | Bind | Unbind | Reset | Add
"""One edit of a repair."""

_KINDS: dict[tuple[str, int], type[EditTerm]] = {
    (k.kind, len(dataclasses.fields(k))): k for k in (Insert, Remove, Swap, Rebind, Bind, Unbind, Reset, Add)}
_VALUES = {"int": clingo.SymbolType.Number, "str": clingo.SymbolType.String}


def edit_term(symbol: clingo.Symbol) -> EditTerm:
    """The typed edit a term of ``edit/1`` stands for."""
    kind = _KINDS.get((symbol.name, len(symbol.arguments))) if symbol.type == clingo.SymbolType.Function else None
    if kind is None:
        raise EncodingError(f"repair.lp shows an unknown edit {symbol}")
    fields = dataclasses.fields(kind)
    if any(a.type != _VALUES[str(f.type)] for f, a in zip(fields, symbol.arguments, strict=True)):
        raise EncodingError(f"repair.lp shows an edit {symbol} whose arguments do not fit {kind.kind}")
    values: list[Any] = [a.number if a.type == clingo.SymbolType.Number else a.string for a in symbol.arguments]
    return kind(*values)  # each value's type checked against its field's above


def edit_text(edit: EditTerm) -> str:
    """The edit as an ASP term, e.g. ``rebind(2,"gripper","g2")``."""
    args = [str(v) if isinstance(v, int) else quote(v) for v in dataclasses.astuple(edit)]
    return f"{edit.kind}({','.join(args)})"

