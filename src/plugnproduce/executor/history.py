"""Past runs: one summary per journal in the runs folder (id, task, cell, start, status, duration, and the speed
factor of simulated devices), newest first.

A summary reads only a journal's first record (``start``) and its last complete one
(``end``, if the run finished), so listing many long runs stays quick.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

TAIL_BYTES = 8192


@dataclass(frozen=True)
class RunSummary:
    """One past run as its journal tells it; ``status`` is ``crashed`` for a run without an end (or still running)."""

    id: str
    path: Path
    task: str
    cell: str
    started: float | None
    status: str
    duration: float | None
    speed: float | None = None
    """How much faster than real time the devices worked, when they were simulated (None: real devices)."""

    def started_text(self) -> str:
        """The start as local ``YYYY-MM-DD HH:MM:SS``, or ``?`` when the journal has no start."""
        if self.started is None:
            return "?"
        return datetime.fromtimestamp(self.started).strftime("%Y-%m-%d %H:%M:%S")

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict; the start in ISO 8601 (UTC), the duration in seconds."""
        started = None if self.started is None else datetime.fromtimestamp(self.started, UTC).isoformat()
        return {"id": self.id, "task": self.task, "cell": self.cell, "start": started, "status": self.status,
                "duration": None if self.duration is None else round(self.duration, 3), "speed": self.speed,
                "journal": str(self.path)}


def _record(line: bytes) -> dict[str, Any] | None:
    try:
        value = json.loads(line)
    except ValueError:
        return None
    return value if isinstance(value, dict) else None


def _last_record(path: Path) -> dict[str, Any] | None:
    """The last complete record (a torn last line, as a crash leaves it, is skipped)."""
    with path.open("rb") as f:
        size = f.seek(0, os.SEEK_END)
        f.seek(max(0, size - TAIL_BYTES))
        lines = f.read().splitlines()
    for line in reversed(lines):
        record = _record(line)
        if record is not None:
            return record
    return None


def summarize(path: str | Path) -> RunSummary:
    """The summary of one journal."""
    p = Path(path)
    with p.open("rb") as f:
        start = _record(f.readline()) or {}
    if start.get("kind") != "start":
        start = {}
    last = _last_record(p) or {}
    started = start.get("t")
    if last.get("kind") == "end":
        status = str(last.get("outcome", "failed"))
    else:
        status = "crashed"
    ended = last.get("t")
    duration = ended - started if isinstance(started, int | float) and isinstance(ended, int | float) else None
    speed = start.get("speed")
    return RunSummary(p.stem, p, str(start.get("task", "?")), str(start.get("cell", "?")),
                      started if isinstance(started, int | float) else None, status, duration,
                      float(speed) if isinstance(speed, int | float) and not isinstance(speed, bool) else None)


def list_runs(folder: str | Path) -> list[RunSummary]:
    """Every journal (``*.jsonl``) in ``folder``, newest first; an empty list if the folder does not exist."""
    root = Path(folder)
    if not root.is_dir():
        return []
    runs = [summarize(p) for p in root.glob("*.jsonl") if p.is_file()]
    return sorted(runs, key=lambda r: (r.started if r.started is not None else r.path.stat().st_mtime, r.id),
                  reverse=True)
