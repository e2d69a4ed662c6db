"""Resume: after a fault or an operator's stop, the rest of a task (or of a goal) planned from the devices' states.

A run's journal holds its task (the ``start`` record's ``task_file``) and where it stopped (its first fault's
step). :func:`stopped_run` reads that back; :func:`rest_of_task` cuts the task there; :func:`replan` plans
what runs on from the states the devices report: the rest of the task (repaired with the reasoner's cheapest
confirmed repair when it is not plausible from there), or the goal planned afresh. The controller reads the
states, shows the plan, and runs it once confirmed (:func:`plugnproduce.controller.resume_run`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from plugnproduce.description.model import Cell, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.knowledge import Knowledge
from plugnproduce.service import checks
from plugnproduce.service.descriptions import cell_and_knowledge, task_from_text, task_text
from plugnproduce.service.journals import report

if TYPE_CHECKING:
    from plugnproduce.description.goalfile import Goal


class NotResumable(PlugNProduceError):
    """A run that cannot be resumed: it succeeded, it has not ended, or its journal does not hold its task."""


class NoWayOn(PlugNProduceError):
    """A finding: nothing plausible continues the run from the states the devices report (``reasons`` say why)."""

    def __init__(self, message: str, reasons: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.reasons = reasons


@dataclass(frozen=True)
class Stopped:
    """A run that ended by a fault or a stop, as its journal tells it."""

    run: str
    """Its id (the journal's file name without ``.jsonl``)."""
    journal: Path
    task: Task
    cell_file: str | None
    outcome: str
    reason: str
    step: int | None
    """The step position it stopped at (its first fault's), None if it stopped before any step began."""
    left: dict[str, str] = field(default_factory=dict)
    """The state each device was left in, as the end record says (after the safe stop)."""
    speed: float | None = None
    """The speed factor of its simulated devices (None: it ran on real devices)."""

    def record(self) -> dict[str, Any]:
        """The fields of the resumed run's ``stopped`` record."""
        return {"run": self.run, "journal": str(self.journal), "outcome": self.outcome, "reason": self.reason,
                "step": self.step}


@dataclass(frozen=True)
class Replan:
    """What runs on after a stopped run: a task planned from the devices' ``states``."""

    stopped: Stopped
    states: dict[str, str]
    task: Task
    plan: str
    """What was planned, in words: ``the rest of task T from step 4`` or ``goal G``."""
    repairs: tuple[str, ...] = field(default=())
    """The edits made so that it is plausible from ``states`` (none: it was plausible as cut)."""

    @property
    def text(self) -> str:
        """The task that runs on, as a task file."""
        return task_text(self.task)

    def record(self) -> dict[str, Any]:
        """The fields of the resumed run's ``replan`` record."""
        return {"plan": self.plan, "states": dict(self.states), "steps": len(self.task.steps),
                "repairs": list(self.repairs), "task_file": self.text}


def stopped_run(run: str | Path) -> Stopped:
    """A run that failed or was stopped, by id (in the runs folder) or journal path (:class:`NotResumable` else)."""
    record = report(run)
    run_id = record.path.name.removesuffix(".jsonl")
    if record.end is None:
        raise NotResumable(f"run {run_id} has no end record: it is still running or it crashed; only a run that "
                           "ended by a fault or a stop can be resumed")
    if record.status == "succeeded":
        raise NotResumable(f"run {run_id} succeeded: nothing to resume")
    text = record.start.get("task_file")
    if not isinstance(text, str):
        raise NotResumable(f"run {run_id}: its journal does not hold its task (written by an older pnp); "
                           "run the task again instead")
    task = task_from_text(text, f"{record.start.get('task', run_id)}.yaml")
    fault = next((r for r in record.of_kind("fault") if r.get("first", True)), None)
    steps = [r.get("step") for r in record.of_kind("step")]
    step = fault.get("step") if fault is not None else (steps[-1] if steps else None)
    cell_file = record.start.get("cell_file")
    left = record.end.get("device_states")
    speed = record.start.get("speed")
    return Stopped(run_id, record.path, task, cell_file if isinstance(cell_file, str) else None, record.status,
                   str(record.end.get("reason", "")), step if isinstance(step, int) else None,
                   {str(d): str(x) for d, x in left.items()} if isinstance(left, dict) else {},
                   float(speed) if isinstance(speed, int | float) and speed > 0 else None)


def rest_of_task(task: Task, step: int | None) -> tuple[Task, int]:
    """The task from the item (a step, or the loop) that holds step position ``step`` on, and the position it
    starts at. A loop runs on from its first step (a value its earlier steps reported is not taken as still
    true); the rest begins earlier still where a step of it takes an output of a step before it. Repeats are
    written out."""
    entries = _entries(task)
    starts = _starts(task, entries)
    at = step if step is not None else 1
    i = max((j for j, s in enumerate(starts) if s <= at), default=0)
    while i > 0 and _needs_earlier(task, starts[i]):
        i -= 1
    doc = {"task": task.name, **({"description": task.description} if task.description else {}),
           "steps": entries[i:]}
    return task_from_text(yaml.safe_dump(doc, sort_keys=False), task.file), starts[i]


def _entries(task: Task) -> list[dict[str, Any]]:
    """The task's items with its repeats written out; a named step of round N > 1 is called ``NAME_N`` (and so are
    the links to it from that round), as names are unique in a task."""
    from plugnproduce.description.taskfile import task_entries

    one = task_entries(task)
    return [_renamed(e, f"_{r + 1}") if r else e for r in range(task.repeat) for e in one]


def _renamed(item: Any, suffix: str) -> Any:
    """A task file item with each step name and each link's ``from`` given ``suffix``."""
    if isinstance(item, list):
        return [_renamed(x, suffix) for x in item]
    if not isinstance(item, dict):
        return item
    out = {k: _renamed(v, suffix) for k, v in item.items()}
    for key in ("name", "from"):
        if isinstance(out.get(key), str) and ("command" in out or key == "from"):
            out[key] = out[key] + suffix
    return out


def _starts(task: Task, entries: list[dict[str, Any]]) -> list[int]:
    """The step position each entry starts at (its steps counted as the task file reader expands them)."""
    starts = [1]
    for j in range(1, len(entries)):
        prefix = task_from_text(yaml.safe_dump({"task": task.name, "steps": entries[:j]}, sort_keys=False), task.file)
        starts.append(len(prefix.steps) + 1)
    return starts


def _needs_earlier(task: Task, start: int) -> bool:
    """Whether a step from position ``start`` on takes an output of a step before it."""
    rest = task.steps[start - 1:]
    names = {s.name for s in rest if s.name}
    return any(link.step not in names for s in rest for link in s.links().values())


def replan(stopped: Stopped, cell_or_path: Cell | str | Path, knowledge: Knowledge | None = None,
           goal: Goal | str | Path | None = None) -> Replan:
    """What runs on after ``stopped`` in a cell whose devices are in the states they reported (``cell_or_path``,
    as :meth:`Cell.reported` gives it): the goal planned afresh, else the rest of the task, repaired when it is
    not plausible from there (:class:`NoWayOn` when nothing is)."""
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    states = {d.id: d.initial for d in the_cell.devices}
    if goal is not None:
        return _replan_goal(stopped, the_cell, k, goal, states)
    rest, start = rest_of_task(stopped.task, stopped.step)
    what = f"the rest of task {stopped.task.name} from step {start}"
    result = checks.check(rest, the_cell, k)
    if result.plausible:
        return Replan(stopped, states, rest, what)
    repaired = checks.assessed_repairs(rest, the_cell, top=1, knowledge=k, checked=result)
    if not repaired:
        raise NoWayOn(f"{what} is not plausible from the devices' states, and no repair makes it so",
                      tuple(str(p) for p in result.problems))
    best = repaired[0].repair
    return Replan(stopped, states, best.task, f"{what}, repaired", tuple(e.text for e in best.edits))


def _replan_goal(stopped: Stopped, cell: Cell, k: Knowledge, goal: Goal | str | Path,
                 states: dict[str, str]) -> Replan:
    from plugnproduce.planning import Unreachable
    from plugnproduce.service.goals import plan

    found = plan(goal, cell, k)
    if isinstance(found, Unreachable):
        raise NoWayOn(f"goal {found.goal.name} cannot be reached from the devices' states", found.reasons)
    return Replan(stopped, states, found.task, f"goal {found.goal.name}")
