"""A task's control flow as records over its flattened steps: loops and branches on an outcome.

A task's steps are one flat sequence of positions (1-based). A loop's body is written
into it twice (its first iteration, then the iterations after it); a branch's steps
follow the step whose outcome decides whether they run. Every path through the task
is this sequence with some ranges skipped or repeated, so each position has one place
in the task file and one set of device states a check can name.
"""

from __future__ import annotations

from plugnproduce.deferred import dataclass


def _local(iri: str) -> str:
    return iri[max(iri.rfind("#"), iri.rfind("/")) + 1:]


@dataclass(frozen=True)
class Loop:
    """A loop of a task: its body runs again and again until one of its steps ends with ``until``
    (the rest of that iteration is skipped), while the last outcome its body reported is
    ``while_outcome``, at most ``max`` times.

    The task's steps hold the body twice: the first iteration (steps ``entry`` to ``first - 1``) and
    the iterations after it (``first`` to ``last``), which start from the states the first one left
    and which the generated chart repeats without unrolling. Indices are 1-based positions in the task.
    """

    entry: int
    first: int
    last: int
    until: str | None
    """The outcome concept (IRI) that ends the loop."""
    max: int | None
    line: int | None = None
    while_outcome: str | None = None
    """The outcome concept (IRI) the loop goes on while (``while:``): checked after each iteration,
    against the last outcome a step of the body reported; any other ends the loop."""

    def path(self, index: int) -> str | None:
        """Which iteration a step position belongs to (``loop iteration 1`` / ``loop iteration 2 and later``)."""
        if self.entry <= index < self.first:
            return "loop iteration 1"
        if self.first <= index <= self.last:
            return "loop iteration 2 and later"
        return None


@dataclass(frozen=True)
class Branch:
    """Steps that run only when step ``step`` ended with ``outcome`` or a more specific outcome
    (``on: {NoPartFound: [...]}``); then the task goes on after the step's branches.

    The branch's steps are positions ``first`` to ``last``, right after the step (or after the
    step's branches written before it). A step's branches exclude each other: an outcome takes the
    branch of the most specific outcome it falls under.
    """

    step: int
    """Position of the step whose outcome decides."""
    outcome: str
    """The outcome concept (IRI)."""
    first: int
    last: int
    line: int | None = None

    def holds(self, index: int) -> bool:
        """Whether step position ``index`` is one of the branch's steps."""
        return self.first <= index <= self.last

    @property
    def path(self) -> str:
        """The branch's name in findings: ``branch NoPartFound at step 3``."""
        return f"branch {_local(self.outcome)} at step {self.step}"


def outermost_first(loops: list[Loop] | tuple[Loop, ...]) -> tuple[Loop, ...]:
    """The loops in the order of their first positions, a loop before the loops inside its body."""
    return tuple(sorted(loops, key=lambda lp: (lp.entry, -lp.last)))


def enclosing(loops: tuple[Loop, ...], index: int) -> tuple[Loop, ...]:
    """The loops whose bodies (either copy) hold step position ``index``, outermost first."""
    return tuple(lp for lp in outermost_first(loops) if lp.entry <= index <= lp.last)


def path_name(loops: tuple[Loop, ...], branches: tuple[Branch, ...], index: int) -> str | None:
    """The path a step position lies on, outermost first (``loop iteration 2 and later, branch
    NoPartFound at step 7``); None on the straight path."""
    parts = [lp.path(index) for lp in outermost_first(loops) if lp.path(index)]
    parts += [b.path for b in sorted(branches, key=lambda b: b.first) if b.holds(index)]
    return ", ".join(p for p in parts if p) or None
