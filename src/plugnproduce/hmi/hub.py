"""The HMI's live picture of the cell and its runs, and the fan-out of events to every open page.

The :class:`Hub` listens to the :class:`~plugnproduce.controller.interfaces.CellSource` and to the
run observer; each change re-infers the offered process commands (``service.capabilities``)
and is pushed to every subscriber as a server-sent event. Changes may arrive from any
thread; delivery always happens on the server's event loop.
"""

from __future__ import annotations

import asyncio
import json
import threading
from collections.abc import Callable
from typing import Any

from plugnproduce import service
from plugnproduce.controller.interfaces import CellSource, CellUpdate, JournalRecord, Runner
from plugnproduce.hmi.views import cell_json
from plugnproduce.service import Cell, DeviceDescription, Knowledge, Task, describe

QUEUE_SIZE = 512
"""Events kept for a page that is slow to read; a page further behind is dropped (its browser reconnects)."""


class Hub:
    """Current cell, device states and runs; every change is published to the subscribed pages."""

    def __init__(self, source: CellSource, runner: Runner, catalogue: list[DeviceDescription],
                 knowledge: Knowledge | None = None) -> None:
        self.source = source
        self.knowledge = knowledge or service.knowledge()
        self.runner = runner
        self.catalogue = catalogue
        self._states = {d.id: d.initial for d in source.cell.devices}
        self._reported: set[str] = set()
        """Devices whose state came from a run (its journal), not from their chart's initial state."""
        self._subscribers: set[asyncio.Queue[str | None]] = set()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._unsubscribe: Callable[[], None] | None = None
        self._lock = threading.Lock()
        self._commands: tuple[Cell, dict[str, Any]] | None = None

    # ------------------------------------------------------------------ lifecycle

    async def start(self) -> None:
        """Subscribe to the cell source and start it (on the server's event loop)."""
        self._loop = asyncio.get_running_loop()
        self._unsubscribe = self.source.subscribe(self._on_cell)
        await self.source.start()

    async def stop(self) -> None:
        """Stop any active run, end every event stream and stop following the cell."""
        active = self.runner.active()
        if active is not None:
            await self.runner.stop(active)
        self.close_streams()
        if self._unsubscribe is not None:
            self._unsubscribe()
        await self.source.stop()

    # ------------------------------------------------------------------ the cell

    @property
    def cell(self) -> Cell:
        """The cell as it is now."""
        return self.source.cell

    @property
    def planning_cell(self) -> Cell:
        """The cell to check, repair, explain and generate in: each device that took part in a run in the state
        the run left it in (as its journal reports), the others in their chart's initial state."""
        with self._lock:
            reported = {d: x for d, x in self._states.items() if d in self._reported}
        return self.cell.reported(reported)

    def states(self) -> dict[str, str]:
        """Each device's current chart state."""
        with self._lock:
            return dict(self._states)

    def commands(self, cell: Cell | None = None) -> dict[str, Any]:
        """Offered process commands (with bindings) and the others with reasons."""
        cell = cell or self.cell
        cached = self._commands
        if cached is not None and cached[0] is cell:
            return cached[1]
        value = service.capabilities(cell, self.knowledge).to_json()
        self._commands = (cell, value)
        return value

    def cell_view(self, cell: Cell | None = None) -> dict[str, Any]:
        """The cell with its devices' states, and the process commands it offers."""
        cell = cell or self.cell
        view = {**cell_json(cell, self.knowledge.taxonomy, self.states()), "refused": self.source.refused()}
        return {"cell": view, "commands": self.commands(cell)}

    def _on_cell(self, update: CellUpdate) -> None:
        with self._lock:
            if update.kind == "plug":
                self._states[update.device] = update.cell.device(update.device).initial
                self._reported.discard(update.device)
            elif update.kind == "unplug":
                self._states.pop(update.device, None)
                self._reported.discard(update.device)
            elif update.kind == "state" and update.state is not None:
                self._states[update.device] = update.state
        if update.kind == "state":
            self.publish("device-state", self._state_event(update.cell, update.device))
            return
        change = {"kind": update.kind, "device": update.device, "reason": update.reason,
                  "url": update.location or None}
        self.publish("cell", {"change": change, **self.cell_view(update.cell)})

    def _state_event(self, cell: Cell, device_id: str) -> dict[str, Any]:
        view = cell_json(cell, self.knowledge.taxonomy, self.states())
        device = next((d for d in view["devices"] if d["id"] == device_id), None)
        return {"device": device_id, "state": device["state"] if device else None,
                "state_concept": device["state_concept"] if device else None}

    # ------------------------------------------------------------------ runs

    async def start_run(self, task: Task) -> str:
        """Start a run of ``task`` in the current cell (RunRefused when it cannot start)."""
        return await self.runner.start(task, self.cell, self.on_run_record)

    async def replan_run(self, run_id: str) -> dict[str, Any]:
        """What would run on after a failed or stopped run, from the states the cell's devices report now."""
        plan = await self.runner.replan(run_id, self.cell)
        return {"run": run_id, "stopped": plan.stopped.record(), **plan.record()}

    async def resume_run(self, run_id: str, seen: dict[str, str] | None) -> str:
        """Resume a failed or stopped run with the plan the operator confirmed; the new run's id."""
        return await self.runner.resume(run_id, self.cell, self.on_run_record, seen)

    def on_run_record(self, run_id: str, record: JournalRecord) -> None:
        """Take in one journal record of a run: device states follow it, and every page hears of it."""
        if record.get("kind") in ("state", "stop") and record.get("device"):  # a stop record: the state reported
            device = str(record["device"])
            with self._lock:
                if device in self._states:
                    self._states[device] = str(record.get("state"))
                    self._reported.add(device)
            self.publish("device-state", self._state_event(self.cell, device))
        self.publish("run", {"run": run_id, "record": record, "text": describe(record)})

    # ------------------------------------------------------------------ event streams

    def subscribe(self) -> asyncio.Queue[str | None]:
        """A queue of formatted server-sent events for one page (None ends the stream)."""
        queue: asyncio.Queue[str | None] = asyncio.Queue(QUEUE_SIZE)
        self._subscribers.add(queue)
        return queue

    def unsubscribe(self, queue: asyncio.Queue[str | None]) -> None:
        """Forget a page's queue."""
        self._subscribers.discard(queue)

    def publish(self, event: str, data: dict[str, Any]) -> None:
        """Send an event to every subscribed page (from any thread)."""
        self._call_in_loop(self._deliver, format_event(event, data))

    def close_streams(self) -> None:
        """End every event stream (the pages' browsers will try to reconnect)."""
        self._call_in_loop(self._deliver, None)

    def _call_in_loop(self, func: Callable[[str | None], None], item: str | None) -> None:
        loop = self._loop
        if loop is None or loop.is_closed():
            return
        try:
            running = asyncio.get_running_loop()
        except RuntimeError:
            running = None
        if running is loop:
            func(item)
        else:
            loop.call_soon_threadsafe(func, item)

    def _deliver(self, item: str | None) -> None:
        for queue in list(self._subscribers):
            try:
                queue.put_nowait(item)
            except asyncio.QueueFull:  # too far behind: end its stream; its browser reconnects and catches up
                self._subscribers.discard(queue)
                while not queue.empty():
                    queue.get_nowait()
                queue.put_nowait(None)


def format_event(event: str, data: dict[str, Any]) -> str:
    """One server-sent event: its name and its data as one line of JSON."""
    return f"event: {event}\ndata: {json.dumps(data, default=str, separators=(',', ':'))}\n\n"
