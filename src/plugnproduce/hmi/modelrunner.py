"""A :class:`~plugnproduce.hmi.interfaces.Runner` that runs a task against the device models.

It stands in for the executor until that exists: it generates the task's code, then
walks each step's paths through the Device State Charts (the regions of a step advance
together, one transition per tick), journalling every command, event and state exactly
as the executor will. No device is talked to. A device that leaves the cell during the
run is a lost connection: the run stops with a fault and every device stays where it is.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from plugnproduce.codegen import GeneratedTask
from plugnproduce.codegen.specific import RegionResult
from plugnproduce.description.model import Cell, ChartTransition, Task
from plugnproduce.executor.journal import Journal, read_journal
from plugnproduce.hmi import pending
from plugnproduce.hmi.interfaces import JournalRecord, RunObserver, RunRefused

log = logging.getLogger(__name__)


class _Journal:
    """A run's journal file and the same records handed to the observer."""

    def __init__(self, run_id: str, path: Path, observer: RunObserver) -> None:
        self.run_id = run_id
        self.path = path
        self._now = 0.0
        self._seq = 0
        self._file = Journal(path, clock=lambda: self._now)
        self._observer = observer

    def write(self, kind: str, **data: Any) -> None:
        self._now = time.time()
        self._seq += 1
        self._file.write(kind, **data)
        self._observer(self.run_id, {"seq": self._seq, "t": round(self._now, 6), "kind": kind, **data})

    def close(self) -> None:
        self._file.close()


@dataclass
class _Run:
    journal: _Journal
    task: asyncio.Task[None] | None = None
    stop_reason: str = ""
    states: dict[str, str] = field(default_factory=dict)


class ModelRunner:
    """Runs tasks against the device models, one at a time, journalling into ``journal_dir``."""

    def __init__(self, cell_now: Callable[[], Cell], journal_dir: Path, tick: float = 0.3) -> None:
        """``cell_now`` gives the cell as it is now (to notice unplugged devices); ``tick`` is seconds per move."""
        self._cell_now = cell_now
        self._dir = Path(journal_dir)
        self._tick = tick
        self._runs: dict[str, _Run] = {}
        self._active: str | None = None
        self._count = 0

    def active(self) -> str | None:
        """The id of the run in progress, if any."""
        return self._active

    def runs(self) -> list[str]:
        """The ids of the runs started since this runner was made, oldest first."""
        return list(self._runs)

    def journal(self, run_id: str) -> list[JournalRecord]:
        """The journal records of a run so far, read back from its file."""
        return read_journal(self._run(run_id).journal.path).records

    async def start(self, task: Task, cell: Cell, observer: RunObserver) -> str:
        """Generate the task's code and start walking it; RunRefused if a run is active or the task implausible."""
        if self._active is not None:
            raise RunRefused(f"run {self._active} is still running; stop it first")
        generation = await asyncio.to_thread(pending.generate, task, cell)
        if generation.generated is None:
            first = generation.check.problems[0]
            raise RunRefused(f"task {task.name!r} cannot run in cell {cell.name!r}: {first.text}")
        self._count += 1
        run_id = f"{time.strftime('%Y%m%d-%H%M%S')}-{self._count}-{re.sub(r'[^A-Za-z0-9_-]', '_', task.name)}"
        run = _Run(_Journal(run_id, self._dir / f"{run_id}.jsonl", observer))
        run.states = {d.id: d.initial for d in cell.devices}
        self._runs[run_id] = run
        self._active = run_id
        run.journal.write("start", task=task.name, cell=cell.name, runner="model",
                          states=dict(run.states), steps=len(task.steps))
        run.task = asyncio.create_task(self._walk(run, generation.generated), name=f"run {run_id}")
        run.task.add_done_callback(self._finished)
        return run_id

    async def stop(self, run_id: str) -> None:
        """Stop a run between two moves; every device stays in the state it reached."""
        run = self._run(run_id)
        if run.task is not None and not run.task.done():
            run.stop_reason = "stopped by the operator"
            run.task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await run.task

    async def finished(self, run_id: str) -> None:
        """Wait until a run has ended (succeeded, failed or stopped)."""
        task = self._run(run_id).task
        if task is not None and not task.done():
            with contextlib.suppress(asyncio.CancelledError):
                await asyncio.shield(task)

    def _run(self, run_id: str) -> _Run:
        if run_id not in self._runs:
            raise KeyError(f"run {run_id!r}")
        return self._runs[run_id]

    def _finished(self, task: asyncio.Task[None]) -> None:
        if not task.cancelled() and task.exception() is not None:
            log.error("model run failed", exc_info=task.exception())

    async def _walk(self, run: _Run, generated: GeneratedTask) -> None:
        j = run.journal
        try:
            for step in generated.steps:
                j.write("step", step=step.step.index, command=step.process.id, bindings=dict(step.binding))
                fault = await self._step(run, step.step.index, step.regions)
                if fault:
                    j.write("fault", **fault)
                    j.write("end", outcome="failed", reason=fault["message"], states=dict(run.states))
                    return
            j.write("end", outcome="succeeded", states=dict(run.states))
        except asyncio.CancelledError:
            j.write("end", outcome="stopped", reason=run.stop_reason or "cancelled", states=dict(run.states))
            raise
        finally:
            j.close()
            self._active = None

    async def _step(self, run: _Run, index: int, regions: list[RegionResult]) -> dict[str, Any] | None:
        """Advance every region of a step one transition per tick; a fault dict if a device is gone."""
        pending_moves: list[tuple[str, list[ChartTransition]]] = [(r.device.id, list(r.path)) for r in regions]
        while any(path for _, path in pending_moves):
            moving = [(device, path.pop(0)) for device, path in pending_moves if path]
            present = {d.id for d in self._cell_now().devices}
            for device, t in moving:
                if device not in present:
                    return {"fault": "connection", "device": device, "step": index, "state": run.states.get(device),
                            "message": f"device {device!r} left the cell during step {index}; "
                                       f"it was last seen in state {run.states.get(device)!r}"}
                if t.request is not None:
                    run.journal.write("command", device=device, command=t.request.name, step=index)
            await asyncio.sleep(self._tick)
            for device, t in moving:
                run.states[device] = t.target
                run.journal.write("state", device=device, state=t.target, step=index)
                for sent in t.sends:
                    run.journal.write("event", device=device, event=sent.name, step=index)
        return None
