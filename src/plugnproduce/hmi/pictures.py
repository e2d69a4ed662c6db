"""Pictures of charts for the page (SVG drawn by :func:`plugnproduce.drawing.render_chart`, in memory), and the
charts generated for recent tasks, kept in memory so the page can fetch them by id."""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from pathlib import Path

from plugnproduce.codegen.outputs import GeneratedChart
from plugnproduce.description.model import DeviceDescription
from plugnproduce.drawing import PlanStep, find_plan, render_chart
from plugnproduce.errors import UnknownName
from plugnproduce.statechart import parse_chart, write_chart


class _Bounded(OrderedDict[str, object]):
    def __init__(self, limit: int) -> None:
        super().__init__()
        self.limit = limit

    def keep(self, key: str, value: object) -> None:
        self[key] = value
        self.move_to_end(key)
        while len(self) > self.limit:
            self.popitem(last=False)


class Pictures:
    """SVG pictures of chart files and of generated charts, drawn once and cached."""

    def __init__(self, limit: int = 64) -> None:
        self._cache = _Bounded(limit)
        self._lock = threading.Lock()

    def of_file(self, path: str | Path) -> bytes:
        """The picture of a chart file (redrawn when the file changes)."""
        p = Path(path)
        key = f"file:{p}:{p.stat().st_mtime_ns}"
        return self._cached(key, lambda: render_chart(p, "svg", p))

    def of_device(self, device: DeviceDescription) -> bytes:
        """The picture of the Device State Chart a device carries (a discovered device's has no file on disk)."""
        key = "device:" + hashlib.sha256(write_chart(device.chart)).hexdigest()
        return self._cached(key, lambda: render_chart(device.chart, "svg", device.chart_file,
                                                      name=Path(device.chart_file).stem))

    def of_chart(self, chart: GeneratedChart, step: int | None = None) -> bytes:
        """The picture of a generated chart; of a task chart, with ``step`` (from 1) expanded."""
        key = f"chart:{step}:" + hashlib.sha256(chart.data).hexdigest()

        return self._cached(key, lambda: render_chart(parse_chart(chart.data, chart.name), "svg", chart.name,
                                                      name="chart", expand=step))

    def _cached(self, key: str, draw: Callable[[], bytes]) -> bytes:
        with self._lock:
            hit = self._cache.get(key)
        if isinstance(hit, bytes):
            return hit
        data = draw()
        with self._lock:
            self._cache.keep(key, data)
        return data



def steps_of(chart: GeneratedChart) -> tuple[PlanStep, ...]:
    """The steps a generated task chart runs, in order (none for a chart without a plan of processes)."""
    plan = find_plan(parse_chart(chart.data, chart.name))
    return plan.steps if plan and plan.is_task else ()

class GeneratedCharts:
    """The charts generated for the last few tasks, by generation id."""

    def __init__(self, limit: int = 16) -> None:
        self._store = _Bounded(limit)
        self._lock = threading.Lock()

    def add(self, charts: Sequence[GeneratedChart]) -> str:
        """Keep a generation's charts; its id is a digest of their content."""
        digest = hashlib.sha256(b"".join(c.name.encode() + b"\0" + c.data for c in charts)).hexdigest()[:16]
        with self._lock:
            self._store.keep(digest, {c.name: c for c in charts})
        return digest

    def chart(self, generation: str, name: str) -> GeneratedChart:
        """One chart of a generation (:class:`UnknownName` if either is unknown)."""
        with self._lock:
            charts = self._store.get(generation)
        if not isinstance(charts, dict):
            raise UnknownName("generation", generation, detail="generate the task again")
        if name not in charts:
            raise UnknownName("chart", name, charts, owner=f"generation {generation}")
        chart: GeneratedChart = charts[name]
        return chart
