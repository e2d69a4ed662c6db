"""Pictures of charts for the page (SVG drawn by :mod:`plugnproduce.service.drawings`, in memory), and the charts
generated for recent tasks, kept in memory so the page can fetch them by id."""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.errors import UnknownName
from plugnproduce.service import drawings

if TYPE_CHECKING:
    from plugnproduce.service import DeviceDescription, GeneratedChart


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
        return self._cached(key, lambda: drawings.picture_of_file(p))

    def of_device(self, device: DeviceDescription) -> bytes:
        """The picture of the Device State Chart a device carries (a discovered device's has no file on disk)."""
        key = "device:" + hashlib.sha256(drawings.device_chart(device)).hexdigest()
        return self._cached(key, lambda: drawings.picture_of_device(device))

    def of_chart(self, chart: GeneratedChart, step: int | None = None) -> bytes:
        """The picture of a generated chart; of a task chart, with ``step`` (from 1) expanded."""
        key = f"chart:{step}:" + hashlib.sha256(chart.data).hexdigest()
        return self._cached(key, lambda: drawings.picture_of_chart(chart, step))

    def _cached(self, key: str, draw: Callable[[], bytes]) -> bytes:
        with self._lock:
            hit = self._cache.get(key)
        if isinstance(hit, bytes):
            return hit
        data = draw()
        with self._lock:
            self._cache.keep(key, data)
        return data


steps_of = drawings.task_steps
"""The steps a generated task chart runs, in order (none for a chart without a plan of processes)."""


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
