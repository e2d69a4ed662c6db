"""Verification of a generated program (design: code generation, point 4).

Every interleaving of the Task State Chart with the cell's device charts is explored, each a
session of the project's SCXML runtime, the devices' delays left open: the program is proved
when every run reaches ``done`` with no deadlock, no request a device refuses and no missing
argument; otherwise the shortest counterexample is told at the description lines it came from.
"""

from __future__ import annotations

from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.model import Cell
from plugnproduce.verification.results import INCONCLUSIVE, PROVED, REFUTED, Budget, TraceStep, Verification
from plugnproduce.verification.search import search
from plugnproduce.verification.trace import explain
from plugnproduce.verification.world import ClosedWorld

__all__ = ["INCONCLUSIVE", "PROVED", "REFUTED", "Budget", "TraceStep", "Verification", "verify"]


def verify(generated: GeneratedTask, cell: Cell, budget: Budget | None = None) -> Verification:
    """Explore every interleaving of ``generated`` on ``cell`` within ``budget`` (default :class:`Budget`)."""
    found = search(ClosedWorld(generated, cell), budget or Budget())
    name, cell_name = generated.task.name, cell.name
    if found.violation is not None and found.moves is not None:
        trace = explain(ClosedWorld(generated, cell), found.moves, found.violation)
        return Verification(name, cell_name, REFUTED, found.states, found.transitions, found.seconds,
                            found.violation.message, trace)
    if found.exhausted:
        return Verification(name, cell_name, INCONCLUSIVE, found.states, found.transitions, found.seconds,
                            found.exhausted + " before every interleaving was explored")
    return Verification(name, cell_name, PROVED, found.states, found.transitions, found.seconds)
