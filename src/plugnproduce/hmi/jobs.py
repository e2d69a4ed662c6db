"""The HMI's expensive requests as jobs a worker process runs: validate, check, repair, explain, generate, import.

Each job takes plain, picklable values (the editor's task, the cell as planned) and returns what the
route answers (JSON-ready data), so a worker can be stopped at any moment without leaving anything
half-done in the server. A worker holds the server's knowledge and catalogue, given once when it starts
(:func:`start_worker`); see :mod:`plugnproduce.hmi.work` for the pool, the budgets and cancellation.
"""

from __future__ import annotations

import os
import resource
import signal
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from plugnproduce import service
from plugnproduce.errors import PlugNProduceError
from plugnproduce.hmi import taskfiles
from plugnproduce.hmi.schemas import TaskIn
from plugnproduce.hmi.views import editor_rows, task_json
from plugnproduce.service import Budget, Cell, DeviceDescription, GeneratedChart, Knowledge, Task

T = TypeVar("T")


@dataclass
class _Context:
    knowledge: Knowledge | None = None
    catalogue: list[DeviceDescription] | None = None


_worker = _Context()
"""What the server gave this worker process when it started."""


def start_worker(knowledge: Knowledge, catalogue: list[DeviceDescription], memory: int | None) -> None:
    """Initialise a worker process: keep the server's knowledge and catalogue; let a job use at most ``memory``
    bytes of address space more than the worker has now (a job over it fails with MemoryError); leave Ctrl-C
    to the server, which stops its workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # should it arrive all the same
    _worker.knowledge, _worker.catalogue = knowledge, catalogue
    if memory is not None:
        limit = _address_space() + memory
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def _address_space() -> int:
    """The bytes of address space this process uses (0 where the system does not say)."""
    try:
        pages = int(Path("/proc/self/statm").read_text(encoding="ascii").split()[0])
    except (OSError, ValueError, IndexError):
        return 0
    return pages * os.sysconf("SC_PAGE_SIZE")


class OverMemory(PlugNProduceError):
    """A job needed more memory than its budget (raised once the job's memory is free again)."""


def call(function: Callable[..., T], *args: Any) -> T:
    """``function(*args)``; a MemoryError is reported as :class:`OverMemory` once the job's frames and data are
    gone, so that the worker has the memory to report it and goes on."""
    try:
        return function(*args)
    except MemoryError:
        pass  # leaving this block drops the traceback, and with it everything the job held
    raise OverMemory


def ready() -> None:
    """Nothing: a first job that gets the workers started."""


def _knowledge() -> Knowledge:
    return _worker.knowledge or service.knowledge()


def _catalogue() -> list[DeviceDescription]:
    if _worker.catalogue is None:
        _worker.catalogue = service.catalogue(knowledge=_knowledge())
    return _worker.catalogue


def _rows(problems: list[dict[str, Any]], task: Task) -> list[dict[str, Any]]:
    """Add to each problem the editor row of its step (steps repeat: step 5 of 2 rows is row 0, round 3;
    a loop's later iterations are its round 2) and the path it lies on (``branch NoPartFound at step 2``)."""
    rows = editor_rows(task)
    for p in problems:
        step = p.get("step")
        if isinstance(step, int) and step in rows:
            p["row"], p["round"] = rows[step]
            p["path"] = task.path(step)
    return problems


def validate(task: TaskIn) -> dict[str, Any]:
    """Schema, SHACL shapes and structure, as ``pnp validate`` does; each problem names its editor field."""
    return taskfiles.validate_task(task, _knowledge())


def check(task: TaskIn, cell: Cell) -> dict[str, Any]:
    """``service.check``: per step its bindings and device states, and every problem at its step and row."""
    model = task.to_task()
    result = service.check(model, cell, _knowledge()).to_json()
    problems = result["problems"]
    if not isinstance(problems, list):
        raise TypeError(f"a check result's problems are a list; found {type(problems).__name__}")
    result["problems"] = _rows(problems, model)
    return result


def repair(task: TaskIn, cell: Cell, top: int) -> dict[str, Any]:
    """The check's problems and, for an implausible task, the ``top`` assessed repairs, each with its task."""
    model, k = task.to_task(), _knowledge()
    result = service.check(model, cell, k)
    repairs = [] if result.plausible else service.assessed_repairs(model, cell, _catalogue(), top, k)
    return {
        "plausible": result.plausible,
        "problems": _rows([p.to_json() for p in result.problems], model),
        "repairs": [{**r.to_json(), "task": task_json(r.repair.task)} for r in repairs],
    }


def explain(task: TaskIn, cell: Cell, step: int) -> dict[str, Any]:
    """``service.explain_step`` and ``service.explain_plausible`` of one step."""
    model, k = task.to_task(), _knowledge()
    why = service.explain_plausible(model, cell, step, k)
    return {**service.explain_step(model, cell, step, k).to_json(), **why.to_json()}


def generate(task: TaskIn, cell: Cell) -> tuple[dict[str, Any], list[GeneratedChart]]:
    """The check's answer, the verification's for a plausible task and, for a proved program, its generated
    charts (the route files them for the page)."""
    model = task.to_task()
    result = service.generation(model, cell, knowledge=_knowledge(), verify=Budget())
    out: dict[str, Any] = {"plausible": result.check.plausible,
                           "problems": _rows([p.to_json() for p in result.check.problems], model),
                           "verification": result.verification.to_json() if result.verification else None}
    return out, list(result.charts)


def import_yaml(data: bytes, filename: str) -> dict[str, Any]:
    """A YAML task description read with the task file's hardened reader, as the editor's JSON."""
    return task_json(taskfiles.import_yaml(data, filename))


def explain_command(cell: Cell, command: str) -> dict[str, Any]:
    """``service.explain_process`` and ``service.explain_offered`` of one process command."""
    k = _knowledge()
    why = service.explain_offered(cell, command, k, _catalogue())
    return {**service.explain_process(cell, command, k).to_json(), **why.to_json()}


def plan_goal(data: bytes, filename: str, cell: Cell) -> dict[str, Any]:
    """``service.plan`` of a goal given as YAML: the plan's steps and task (as the editor's JSON, and as a task
    file) with the check's verdict and its estimated cycle time (``pnp check``'s, null when there is none), or
    why no plan reaches the goal and what to buy."""
    k = _knowledge()
    goal = service.goal_from_text(data, filename)
    found = service.plan(goal, cell, k, _catalogue())
    if isinstance(found, service.Unreachable):
        buy = found.purchase
        return {"goal": goal.name, "reachable": False, "reasons": list(found.reasons),
                "purchase": None if buy is None else {"device": buy.id, "label": buy.label, "cost": buy.cost}}
    checked = service.check(found.task, cell, k)
    estimate = service.cycle_time(found.task, cell, k, checked)
    steps = [{"step": s.index, "command": s.command, "bind": dict(s.bind),
              "params": {n: (v.to_plain() if hasattr(v, "to_plain") else v) for n, v in s.params.items()}}
             for s in found.task.one_round()[:found.steps]]
    return {"goal": goal.name, "reachable": True, "steps": steps, "until": goal.until and goal.until.rsplit("#", 1)[-1],
            "plausible": checked.plausible, "text": found.text, "task": task_json(found.task),
            "cycle_time": estimate.to_json() if estimate is not None else None}
