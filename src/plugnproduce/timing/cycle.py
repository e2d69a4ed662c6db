"""A task's estimated cycle time, step by step and per loop iteration, as plain data (estimated in
:mod:`~plugnproduce.timing.estimate`, which names these too; what reads an estimate kept before needs nothing of
code generation)."""

from __future__ import annotations

from dataclasses import field
from typing import Any

from plugnproduce.deferred import dataclass


@dataclass(frozen=True)
class StepTime:
    """One step's estimated time."""

    step: int
    command: str
    seconds: float


@dataclass(frozen=True)
class LoopTime:
    """A loop's estimated time per iteration, and how many iterations are counted."""

    entry: int
    last: int
    first_iteration: float
    later_iteration: float
    count: int | None
    """The known number of iterations (None: it ends on an outcome; counted once)."""


@dataclass(frozen=True)
class CycleTime:
    """A task's estimated cycle time."""

    steps: tuple[StepTime, ...]
    loops: tuple[LoopTime, ...] = ()
    total: float = 0.0
    notes: tuple[str, ...] = field(default=())
    """What the total leaves out or assumes (a loop of unknown count, a pose known only at run time)."""

    def to_json(self) -> dict[str, Any]:
        """The estimate as JSON (seconds rounded to the millisecond)."""
        return {"total_seconds": round(self.total, 3),
                "steps": [{"step": s.step, "command": s.command, "seconds": round(s.seconds, 3)} for s in self.steps],
                "loops": [{"entry": lp.entry, "last": lp.last, "first_iteration_seconds": round(lp.first_iteration, 3),
                           "later_iteration_seconds": round(lp.later_iteration, 3), "count": lp.count}
                          for lp in self.loops],
                "notes": list(self.notes)}
