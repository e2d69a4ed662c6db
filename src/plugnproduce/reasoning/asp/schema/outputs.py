"""Output predicates: what the encodings show (offered processes, reasons, plausibility, repairs, batches)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import clingo

from plugnproduce.reasoning.asp.terms import Atom, codec, predicate

if TYPE_CHECKING:
    from plugnproduce.reasoning.asp.schema.edits import EditTerm


def _edit_text(edit: Any) -> str:
    from plugnproduce.reasoning.asp.schema.edits import edit_text

    return edit_text(edit)


def _edit_term(symbol: clingo.Symbol) -> Any:
    from plugnproduce.reasoning.asp.schema.edits import edit_term

    return edit_term(symbol)


codec("EditTerm", _edit_text, _edit_term)  # the edits' classes are made by the first repair, not by every check

# ------------------------------------------------------------------ output: offered processes


@predicate("can_play")
class CanPlay(Atom):
    """Device ``d`` can fill role ``r`` of ``p``."""

    p: str
    r: str
    d: str


@predicate("offered")
class Offered(Atom):
    """Process ``p`` is offered in configuration ``c``."""

    c: str
    p: str


@predicate("binding")
class Binding(Atom):
    """A valid role binding of ``p`` in ``c``: a list of devices in reverse role order."""

    c: str
    p: str
    devices: clingo.Symbol


@predicate("no_skill")
class NoSkill(Atom):
    """Why not: no device of ``c`` has skill ``s`` that role ``r`` of ``p`` requires."""

    c: str
    p: str
    r: str
    s: str


@predicate("lacks_state")
class LacksState(Atom):
    """Why not: device ``d`` has the skill but no state of concept ``con``, region state ``i`` of ``r``."""

    c: str
    p: str
    r: str
    d: str
    i: int
    con: str


@predicate("unreachable")
class Unreachable(Atom):
    """Why not: in ``d``'s chart no state of concept ``con`` (region state ``i``+1) is reachable from ``x``."""

    c: str
    p: str
    r: str
    d: str
    i: int
    x: str
    con: str


@predicate("no_argument")
class NoArgument(Atom):
    """Why not: ``d`` could play ``r`` of ``p`` but its request ``req`` needs argument ``q``, which ``p`` lacks."""

    c: str
    p: str
    r: str
    d: str
    req: str
    q: str


# ------------------------------------------------------------------ output: plausibility


@predicate("bound")
class Bound(Atom):
    """Role ``r`` of step ``i`` is played by ``d``."""

    c: str
    t: str
    i: int
    r: str
    d: str


@predicate("at")
class At(Atom):
    """Device ``d`` is in chart state ``x`` when step ``i`` starts (``i`` = steps + 1: at the end)."""

    c: str
    t: str
    i: int
    d: str
    x: str


@predicate("left_by")
class LeftBy(Atom):
    """The state ``d`` is in when step ``i`` starts was left by step ``j`` (0: its initial state)."""

    c: str
    t: str
    i: int
    d: str
    j: int


@predicate("plausible")
class Plausible(Atom):
    """Task ``t`` is plausible in configuration ``c``."""

    c: str
    t: str


@predicate("wrong_state")
class WrongState(Atom):
    """Step ``i``: ``d`` (role ``r``) is in state ``x``, but the role's region starts in concept ``need``."""

    c: str
    t: str
    i: int
    r: str
    d: str
    x: str
    need: str


@predicate("stuck")
class Stuck(Atom):
    """Step ``i``: from state ``x``, ``d``'s chart has no path through role ``r``'s region."""

    c: str
    t: str
    i: int
    r: str
    d: str
    x: str


@predicate("no_device")
class NoDevice(Atom):
    """Step ``i``: no device of ``c`` can play role ``r`` (and the task binds none)."""

    c: str
    t: str
    i: int
    r: str


@predicate("ambiguous")
class Ambiguous(Atom):
    """Step ``i``: role ``r`` is not bound in the task and ``d`` is one of several devices that fit."""

    c: str
    t: str
    i: int
    r: str
    d: str


@predicate("absent")
class Absent(Atom):
    """Step ``i`` binds role ``r`` to ``d``, which is not in the cell."""

    c: str
    t: str
    i: int
    r: str
    d: str


@predicate("cannot_play")
class CannotPlay(Atom):
    """Step ``i`` binds role ``r`` to ``d``, which cannot play it."""

    c: str
    t: str
    i: int
    r: str
    d: str


@predicate("unknown_role")
class UnknownRole(Atom):
    """Step ``i`` binds ``r``, which is no role of its process."""

    c: str
    t: str
    i: int
    r: str


@predicate("unknown_command")
class UnknownCommand(Atom):
    """Step ``i`` names ``p``, which is no known process command."""

    c: str
    t: str
    i: int
    p: str


@predicate("bad_type")
class BadType(Atom):
    """Step ``i`` gives parameter ``n`` a value that is not of its datatype ``ty``."""

    t: str
    i: int
    n: str
    ty: str


@predicate("too_low")
class TooLow(Atom):
    """Step ``i`` gives ``n`` the value ``v`` below its minimum ``bound`` (thousandths)."""

    t: str
    i: int
    n: str
    v: int
    bound: int


@predicate("too_high")
class TooHigh(Atom):
    """Step ``i`` gives ``n`` the value ``v`` above its maximum ``bound`` (thousandths)."""

    t: str
    i: int
    n: str
    v: int
    bound: int


@predicate("unknown_param")
class UnknownParam(Atom):
    """Step ``i`` gives a value for ``n``, which its process does not declare."""

    t: str
    i: int
    n: str


# ------------------------------------------------------------------ output: repair


@predicate("edit")
class Edit(Atom):
    """An edit of an optimal repair: ``insert(I,J,P)``, ``remove(I)``, ``swap(I)``, ``rebind(I,R,D)``, ...
    (:mod:`.edits`)."""

    e: EditTerm


@predicate("left_in")
class LeftIn(Atom):
    """A repaired window leaves device ``d`` in chart state ``x``."""

    d: str
    x: str


@predicate("runs")
class Runs(Atom):
    """In the repaired task, slot ``s`` runs process ``p``; ``i`` is the original step (0: inserted)."""

    s: int
    p: str
    i: int


@predicate("plays")
class Plays(Atom):
    """In the repaired task, role ``r`` of slot ``s`` is played by ``d``; ``explicit`` 1 if written in the task."""

    s: int
    r: str
    d: str
    explicit: int


# ------------------------------------------------------------------ output: per-device abilities (batch)


@predicate("bad_value")
class BadValue(Atom):
    """Parameter ``n`` of step ``i`` of task ``t`` does not fit its process's declaration."""

    t: str
    i: int
    n: str
