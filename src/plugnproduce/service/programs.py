"""Generate and verify: a plausible task's program (its charts), every interleaving of it explored."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.deferred import dataclass
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.knowledge import Knowledge
from plugnproduce.lazy import lazy_module
from plugnproduce.service import checks
from plugnproduce.service.descriptions import CellArg, TaskArg, _devices, as_task, cell_and_knowledge

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce import reasoning
    from plugnproduce.codegen import GeneratedTask
    from plugnproduce.codegen.outputs import GeneratedChart
    from plugnproduce.timing.cycle import CycleTime
    from plugnproduce.verification import Budget, Verification
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner


class ImplausibleTask(PlugNProduceError):
    """A task the plausibility check refuses; ``result`` holds the problems per step."""

    def __init__(self, result: reasoning.CheckResult):
        self.result = result
        super().__init__(f"task {result.task} is not plausible in cell {result.cell}: "
                         + "; ".join(str(p) for p in result.problems))


@dataclass(frozen=True)
class Generated:
    """A task's generated program: the task chart model and every chart written for it."""

    task: GeneratedTask
    charts: list[GeneratedChart]
    verification: Verification | None = None
    """Every interleaving explored (when asked for); the charts are only for a proved program."""


@dataclass(frozen=True)
class Generation:
    """The plausibility check of a task and, when it is plausible (and proved, when verified), its generated
    program (else None), with the verification's answer when it was verified."""

    check: reasoning.CheckResult
    generated: Generated | None
    verification: Verification | None = None

    @property
    def charts(self) -> list[GeneratedChart]:
        """The charts written for the task (none for an implausible or unproved task)."""
        return self.generated.charts if self.generated is not None else []


def _generate_task(the_task: Task, the_cell: Cell, result: reasoning.CheckResult, k: Knowledge) -> GeneratedTask:
    from plugnproduce.codegen import generate_task

    in_units, _ = reasoning.normalised(the_task, k.processes)  # the values in their parameters' units
    return generate_task(in_units, the_cell, result.bindings(), k.processes_by_id, k.taxonomy)


def generation(task_or_path: TaskArg, cell_or_path: CellArg, per_device: bool = False,
               knowledge: Knowledge | None = None, verify: Budget | None = None) -> Generation:
    """Check a task and, when it is plausible, generate its specific process charts, task chart,
    closed-world chart and, with ``per_device``, each device's program.

    With a ``verify`` budget every interleaving of the program is explored first (:func:`verify`)
    and charts are made only for a proved program. An implausible or unproved task is a result
    here (``generated`` is None), not an error.
    """
    the_task, (the_cell, k) = as_task(task_or_path), cell_and_knowledge(cell_or_path, knowledge)
    result = checks.check(the_task, the_cell, k)
    if not result.plausible:
        return Generation(result, None)
    from plugnproduce.codegen.outputs import all_charts

    generated = _generate_task(the_task, the_cell, result, k)
    proof = _verify(generated, the_cell, verify) if verify is not None else None
    if proof is not None and not proof.proved:
        return Generation(result, None, proof)
    return Generation(result, Generated(generated, all_charts(generated, the_cell, per_device), proof), proof)


def generate(task_or_path: TaskArg, cell_or_path: CellArg, per_device: bool = False,
             knowledge: Knowledge | None = None, verify: Budget | None = None) -> Generated:
    """:func:`generation` for a task that must be plausible (else :class:`ImplausibleTask`) and, with a
    ``verify`` budget, proved (else :class:`Unverified`, and no charts are made)."""
    result = generation(task_or_path, cell_or_path, per_device, knowledge, verify)
    if result.generated is not None:
        return result.generated
    if result.verification is not None:
        raise Unverified(result.verification)
    raise ImplausibleTask(result.check)


class Unverified(PlugNProduceError):
    """A generated program that verification refuted, or could not prove within its budget."""

    def __init__(self, verification: Verification):
        self.verification = verification
        super().__init__("; ".join(verification.lines()[:2]))


def verify(task_or_path: TaskArg, cell_or_path: CellArg, budget: Budget | None = None,
           knowledge: Knowledge | None = None) -> Verification:
    """Check and generate a task, then explore every interleaving of its program with the cell's device
    charts within ``budget``: proved, refuted (with the shortest counterexample) or inconclusive.
    Raises :class:`ImplausibleTask` for an implausible task."""
    the_task, (the_cell, k) = as_task(task_or_path), cell_and_knowledge(cell_or_path, knowledge)
    return _verify(plan_run(the_task, the_cell, k), the_cell, budget)


def _verify(generated: GeneratedTask, the_cell: Cell, budget: Budget | None) -> Verification:
    from plugnproduce.verification import verify as explore

    return explore(generated, the_cell, budget)


def plan_run(task_or_path: TaskArg, cell_or_path: CellArg, knowledge: Knowledge | None = None,
             progress: Callable[[str], None] | None = None) -> GeneratedTask:
    """Check a task and generate only what a run needs: the task chart (no closed-world chart, no device
    programs, no chart written). Raises :class:`ImplausibleTask` for an implausible task."""
    the_task, (the_cell, k) = as_task(task_or_path), cell_and_knowledge(cell_or_path, knowledge)
    if not (result := checks.check(the_task, the_cell, k)).plausible:
        raise ImplausibleTask(result)
    if progress is not None:
        progress(f"generating the charts of {len(the_task.steps)} step(s)")
    return _generate_task(the_task, the_cell, result, k)


def cycle_time(task_or_path: TaskArg, cell_or_path: CellArg, knowledge: Knowledge | None = None,
               result: reasoning.CheckResult | None = None) -> CycleTime | None:
    """The estimated cycle time of a task in a cell, step by step (None: the task is not plausible there, or
    its program cannot be generated). ``result``: the task's check, when it was checked already. Read back from
    the cache folder while the task, the cell, the processes and the taxonomy are unchanged
    (:mod:`plugnproduce.timing.kept`)."""
    from plugnproduce.timing.kept import kept_cycle_time

    the_task, (the_cell, k) = as_task(task_or_path), cell_and_knowledge(cell_or_path, knowledge)
    result = result if result is not None else checks.check(the_task, the_cell, k)
    return kept_cycle_time(the_task, the_cell, k, result) if result.plausible else None


def repair_cycle_times(repairs: Sequence[reasoning.AssessedRepair], cell_or_path: CellArg,
                       catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
                       knowledge: Knowledge | None = None) -> list[CycleTime | None]:
    """Each repaired task's estimated cycle time in the cell with the devices its repair buys (None: no estimate).
    Every repair starts from the same task, so their order by it is their order by the time they add; the
    steps they share are estimated once."""
    from plugnproduce import collector
    from plugnproduce.timing.estimate import StepMemo
    from plugnproduce.timing.tasks import task_cycle_time

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    bought: dict[str, DeviceDescription] = {}  # read only when a repair buys a device (the libraries' are many)
    if any(r.repair.added_devices for r in repairs):
        bought = {d.id: d for d in (k.devices if catalogue_or_folder is None else _devices(catalogue_or_folder, k))}
    out: list[CycleTime | None] = []
    memo = StepMemo()
    with collector.paused():  # the repaired tasks' programs are long-lived while estimated, not cyclic garbage
        for r in repairs:
            cell = the_cell
            for device in r.repair.added_devices:
                cell = cell.with_device(bought[device])
            out.append(task_cycle_time(r.repair.task, cell, k, r.checked, memo))  # checked by the assessment
    return out
