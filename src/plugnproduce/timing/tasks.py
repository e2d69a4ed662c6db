"""A task's cycle time in a cell: checked, generated and estimated in one go (no run, no I/O)."""

from __future__ import annotations

from plugnproduce.codegen.task import generate_task
from plugnproduce.description.model import Cell, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.knowledge import Knowledge
from plugnproduce.reasoning import CheckResult, check, normalised
from plugnproduce.timing.estimate import CycleTime, StepMemo, estimate_task


def task_cycle_time(task: Task, cell: Cell, knowledge: Knowledge,
                    result: CheckResult | None = None, memo: StepMemo | None = None) -> CycleTime | None:
    """The estimated cycle time of ``task`` in ``cell`` (None: not plausible there, or no program for it);
    ``result``: the task's check in the cell, when it was checked already; ``memo``: the steps of tasks
    estimated before, which this one reuses where they are the same (:class:`StepMemo`)."""
    result = result if result is not None else check(task, cell, knowledge)
    if not result.plausible:
        return None
    in_units, _ = normalised(task, knowledge.processes)
    try:
        generated = generate_task(in_units, cell, result.bindings(), knowledge.processes_by_id, knowledge.taxonomy)
    except PlugNProduceError:
        return None
    return estimate_task(generated, memo)
