"""The executor as the HMI's :class:`~plugnproduce.controller.interfaces.Runner`.

A run takes the one path of every run, :func:`~plugnproduce.controller.run.planned_run` (as ``pnp run``
does): the task is checked for the cell as it is now, each device in the state it reports, only its
task chart is generated, and it runs against the cell's devices at the endpoints discovery found,
journalling into the runs folder. A device the cell source sees leave during
the run is a lost device: the run stops with a fault.
One run at a time.
"""

from __future__ import annotations

import asyncio
import logging
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from plugnproduce.controller.interfaces import CellSource, CellUpdate, JournalRecord, RunObserver, RunRefused
from plugnproduce.controller.resume import continue_run, replan_live
from plugnproduce.controller.run import StateNotReported, planned_run
from plugnproduce.controller.simcell import SimulatedCellSource
from plugnproduce.description.model import Cell, Task
from plugnproduce.errors import UnknownName
from plugnproduce.executor.journal import read_journal
from plugnproduce.executor.run import TaskRun  # the type of a run
from plugnproduce.knowledge import Knowledge
from plugnproduce.service import ImplausibleTask, NoWayOn, Replan, knowledge, new_run_id, stopped_run

log = logging.getLogger(__name__)


@dataclass
class _Run:
    run: TaskRun
    task: asyncio.Task[object]


class ExecutorRunner:
    """Runs tasks on the devices of ``source``'s cell, one at a time, journalling into ``runs_dir``."""

    def __init__(self, source: CellSource, runs_dir: Path, knowledge: Knowledge | None = None) -> None:
        self._dir = Path(runs_dir)
        self._source = source
        self._knowledge = knowledge
        self._runs: dict[str, _Run] = {}
        self._loop: asyncio.AbstractEventLoop | None = None
        source.subscribe(self._on_cell)

    def active(self) -> str | None:
        """The id of the run in progress, if any."""
        return next((run_id for run_id, r in self._runs.items() if not r.task.done()), None)

    def runs(self) -> list[str]:
        """The ids of the runs started since this runner was made, oldest first."""
        return list(self._runs)

    def journal(self, run_id: str) -> list[JournalRecord]:
        """The journal records of a run so far, read back from its file."""
        return read_journal(self._run(run_id).run.journal_path).records

    async def start(self, task: Task, cell: Cell, observer: RunObserver) -> str:
        """Check and generate ``task`` for ``cell`` and start running it; RunRefused if a run is active or
        the task implausible. Returns once the run's journal has its ``start`` record."""
        active = self.active()
        if active is not None:
            raise RunRefused(f"run {active} is still running; stop it first")
        if isinstance(self._source, SimulatedCellSource):
            self._source.prepare_run(task)  # its default bin, for a task that loops on a localized pose
        run_id = new_run_id(re.sub(r"[^A-Za-z0-9_-]", "_", task.name))
        observe, started = self._observer(run_id, observer)
        try:  # planned from the state each device reports, not its chart's initial state
            run = await planned_run(task, cell, cell, self._dir / f"{run_id}.jsonl", knowledge=self._knowledge,
                                    observer=observe, speed=self._speed())
        except StateNotReported as exc:
            raise RunRefused(f"task {task.name!r} cannot be planned in cell {cell.name!r}: {exc}") from exc
        except ImplausibleTask as exc:
            first = exc.result.problems[0]
            raise RunRefused(f"task {task.name!r} cannot run in cell {cell.name!r}: {first.text}") from exc
        return await self._launch(run_id, run, started)

    async def replan(self, run_id: str, cell: Cell) -> Replan:
        """What runs on after run ``run_id`` (failed or stopped), planned from the states ``cell``'s devices report
        now (RunRefused while it runs or when nothing plausible goes on; NotResumable for a run that succeeded)."""
        entry = self._run(run_id)
        if not entry.task.done():
            raise RunRefused(f"run {run_id} is still running; stop it first")
        k = await self._known()
        try:
            stopped = await asyncio.to_thread(stopped_run, entry.run.journal_path)
            return await replan_live(stopped, cell, cell, k)
        except (StateNotReported, NoWayOn) as exc:
            raise RunRefused(f"run {run_id} cannot be resumed: {exc}") from exc

    async def resume(self, run_id: str, cell: Cell, observer: RunObserver, seen: dict[str, str] | None = None) -> str:
        """Resume run ``run_id``: re-plan it (:meth:`replan`) and start the plan, its journal beginning with the
        stop, the re-plan and the operator's confirmation; ``seen``: the devices' states of the plan the operator
        confirmed (RunRefused when they have changed since). Returns the new run's id."""
        active = self.active()
        if active is not None:
            raise RunRefused(f"run {active} is still running; stop it first")
        plan = await self.replan(run_id, cell)
        if seen is not None and seen != plan.states:
            raise RunRefused("the devices changed since the plan was shown; look at the new plan and confirm it")
        if isinstance(self._source, SimulatedCellSource):
            self._source.prepare_run(plan.task)  # the session's bin, as the run it resumes had
        new_id = new_run_id(re.sub(r"[^A-Za-z0-9_-]", "_", plan.task.name))
        observe, started = self._observer(new_id, observer)
        try:
            run = await continue_run(plan, cell, cell, await self._known(), "the operator",
                                     self._dir / f"{new_id}.jsonl", observe, self._speed())
        except NoWayOn as exc:
            raise RunRefused(str(exc)) from exc
        return await self._launch(new_id, run, started)

    def _speed(self) -> float | None:
        """The speed factor of the simulated devices runs go to (None: real devices)."""
        return self._source.sim.speed if isinstance(self._source, SimulatedCellSource) else None

    async def _known(self) -> Knowledge:
        """The knowledge runs are planned with (the built-in library unless given)."""
        if self._knowledge is None:
            self._knowledge = await asyncio.to_thread(knowledge)
        return self._knowledge

    @staticmethod
    def _observer(run_id: str, observer: RunObserver) -> tuple[Callable[[JournalRecord], None], asyncio.Event]:
        """The run's record observer, passing each record on with the run id; the event it sets on the first."""
        started = asyncio.Event()

        def observe(record: JournalRecord) -> None:
            started.set()
            observer(run_id, record)

        return observe, started

    async def _launch(self, run_id: str, run: TaskRun, started: asyncio.Event) -> str:
        """Start ``run``; return once its journal has its ``start`` record."""
        self._loop = asyncio.get_running_loop()
        running = asyncio.create_task(run.run(), name=f"run {run_id}")
        running.add_done_callback(self._finished)
        self._runs[run_id] = _Run(run, running)
        waiting = asyncio.create_task(started.wait())
        await asyncio.wait({waiting, running}, return_when=asyncio.FIRST_COMPLETED)
        waiting.cancel()
        if not started.is_set():  # it ended before its journal began (e.g. the runs folder cannot be written)
            del self._runs[run_id]
            running.result()
        return run_id

    async def stop(self, run_id: str) -> None:
        """Stop a run (no further command goes out) and wait until it has ended."""
        entry = self._run(run_id)
        if not entry.task.done():
            entry.run.stop("stopped by the operator")
        await self.finished(run_id)

    async def finished(self, run_id: str) -> None:
        """Wait until a run has ended (succeeded, failed or stopped)."""
        await asyncio.wait({self._run(run_id).task})  # a run that crashed is logged by _finished

    def _run(self, run_id: str) -> _Run:
        if run_id not in self._runs:
            raise UnknownName("run", run_id, self._runs)
        return self._runs[run_id]

    def _finished(self, task: asyncio.Task[object]) -> None:
        if not task.cancelled() and task.exception() is not None:
            log.error("run %s crashed", task.get_name(), exc_info=task.exception())

    def _on_cell(self, update: CellUpdate) -> None:
        """A device that leaves the cell during a run is lost to the run (called from any thread)."""
        if update.kind == "unplug" and self._loop is not None and not self._loop.is_closed():
            self._loop.call_soon_threadsafe(self._lost, update.device)

    def _lost(self, device: str) -> None:
        active = self.active()
        if active is not None:
            self._runs[active].run.device_lost(device, "the device left the cell (SSDP byebye)")
