"""Cycle time in a batch: each configuration's estimated time per plausible task, and the Pareto front of
cost × cycle time.

A configuration's times depend only on the devices its tasks bind, which is what the engine's key of the
configuration says (:meth:`.feasibility.Feasibility.key_all`): each key is estimated once (check, code
generation, estimate), from the first configuration that has it.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass

from plugnproduce.batch.batches import Configuration, Engine, task_names
from plugnproduce.batch.feasibility import MEMORY, Key
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.knowledge import Knowledge
from plugnproduce.timing.tasks import task_cycle_time

Times = dict[str, float | None]
"""Task name → estimated seconds (None: not plausible in the configuration)."""


class CycleTimes:
    """Adds ``cycle_time`` to a batch's JSONL lines: per task, the estimated seconds (null where the task is not
    plausible), and ``cost``, the configuration's devices' cost."""

    def __init__(self, engine: Engine, catalogue: Sequence[DeviceDescription], tasks: Sequence[Task],
                 knowledge: Knowledge) -> None:
        self.engine = engine
        self._devices = {d.id: d for d in catalogue}
        self._tasks = task_names(tasks)
        self._knowledge = knowledge
        self._known: dict[Key, Times] = {}

    def times(self, config: Configuration, plausible: Sequence[str]) -> Times:
        """The configuration's estimated seconds per task (only the plausible ones are estimated)."""
        key = self.engine.feasibility.key_all(self.engine.mask(config))
        found = self._known.get(key)
        if found is None:
            if len(self._known) >= MEMORY:
                self._known.clear()
            cell = Cell(config.name, tuple(self._devices[d] for d in config.devices))
            found = self._known[key] = {name: self._seconds(task, cell) if name in plausible else None
                                        for name, task in self._tasks}
        return found

    def _seconds(self, task: Task, cell: Cell) -> float | None:
        estimate = task_cycle_time(task, cell, self._knowledge)
        return round(estimate.total, 3) if estimate is not None else None

    def cost(self, config: Configuration) -> float:
        """What the configuration's devices cost (``pnp:cost``)."""
        return sum(self._devices[d].cost for d in config.devices)

    def annotate(self, line: str, config: Configuration) -> dict[str, object]:
        """A report line (JSON) with the configuration's ``cost`` and ``cycle_time`` added."""
        row: dict[str, object] = json.loads(line)
        plausible = row.get("plausible")
        row["cost"] = self.cost(config)
        row["cycle_time"] = self.times(config, plausible if isinstance(plausible, list) else [])
        return row


@dataclass(frozen=True)
class Point:
    """A configuration on the cost × cycle-time plane (every task plausible; the time is their sum)."""

    config: str
    devices: tuple[str, ...]
    cost: float
    cycle_time: float

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"config": self.config, "devices": list(self.devices), "cost": self.cost,
                "cycle_time": self.cycle_time}


class ParetoFront:
    """The configurations no other beats in both cost and cycle time (ties: the first one seen stays)."""

    def __init__(self) -> None:
        self.points: list[Point] = []

    def add(self, row: dict[str, object]) -> None:
        """Consider one annotated row (:meth:`CycleTimes.annotate`); one with a task not plausible is left out."""
        times = row.get("cycle_time")
        if not isinstance(times, dict) or not times or any(v is None for v in times.values()):
            return
        devices = row.get("devices")
        point = Point(str(row["config"]), tuple(devices) if isinstance(devices, list) else (),
                      float(row["cost"]), round(sum(times.values()), 3))  # type: ignore[arg-type]
        if any(_dominates(p, point) or (p.cost, p.cycle_time) == (point.cost, point.cycle_time)
               for p in self.points):
            return
        self.points = [p for p in self.points if not _dominates(point, p)] + [point]

    def front(self) -> list[Point]:
        """The front, cheapest first."""
        return sorted(self.points, key=lambda p: (p.cost, p.cycle_time, p.config))


def _dominates(a: Point, b: Point) -> bool:
    return a.cost <= b.cost and a.cycle_time <= b.cycle_time and (a.cost, a.cycle_time) != (b.cost, b.cycle_time)
