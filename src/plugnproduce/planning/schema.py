"""The planner's predicates (rules/plan.lp): what it reads besides the cell's facts, and what it shows."""

from __future__ import annotations

from plugnproduce.reasoning.asp.terms import Atom, predicate

# ------------------------------------------------------------------ input


@predicate("need")
class Need(Atom):
    """Goal item ``g`` (1-based, in order) runs process command ``p``."""

    g: int
    p: str


@predicate("fixed")
class Fixed(Atom):
    """Goal item ``g`` fixes the value of parameter ``n``."""

    g: int
    n: str


@predicate("pinned")
class Pinned(Atom):
    """Goal item ``g`` binds role ``r`` to device ``d``."""

    g: int
    r: str
    d: str


@predicate("feeds")
class Feeds(Atom):
    """``n`` is the first parameter of ``p`` with quantity ``q`` and datatype ``ty``: an output may feed it."""

    p: str
    n: str
    q: str
    ty: str


@predicate("gives")
class Gives(Atom):
    """``p`` outputs ``o``, of quantity ``q`` and datatype ``ty``."""

    p: str
    o: str
    q: str
    ty: str


@predicate("reports")
class Reports(Atom):
    """Command ``p`` may report the outcome the goal loops until (or a more specific one)."""

    p: str


@predicate("looping")
class Looping(Atom):
    """The plan is a loop's body."""


@predicate("end_state")
class EndState(Atom):
    """Device ``d`` must be left in a state of concept ``k``."""

    d: str
    k: str


# ------------------------------------------------------------------ output


@predicate("act")
class Act(Atom):
    """Step ``t`` runs command ``p``."""

    t: int
    p: str


@predicate("bound")
class Bound(Atom):
    """Step ``t`` binds role ``r`` to device ``d``."""

    t: int
    r: str
    d: str


@predicate("does")
class Does(Atom):
    """Step ``t`` is goal item ``g``."""

    g: int
    t: int


@predicate("link")
class PlanLink(Atom):
    """Parameter ``n`` of step ``t`` takes output ``o`` of step ``t0``."""

    t: int
    n: str
    t0: int
    o: str


@predicate("blind")
class Blind(Atom):
    """Parameter ``n`` of step ``t`` takes its default although the cell could measure it."""

    t: int
    n: str


@predicate("wasted")
class Wasted(Atom):
    """At horizon ``h``, output ``o`` of step ``t`` is one some command could take, and no later step takes it."""

    h: int
    t: int
    o: str
