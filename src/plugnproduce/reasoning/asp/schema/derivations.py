"""Output predicates a derivation reads back: the intermediate facts of roles.lp (show_derivation.lp)."""

from __future__ import annotations

from plugnproduce.reasoning.asp.terms import Atom, predicate


@predicate("walk")
class Walk(Atom):
    """Device ``d`` can be in chart state ``x`` when role ``r``'s region of ``p`` visits its ``i``-th state."""

    p: str
    r: str
    d: str
    i: int
    x: str
