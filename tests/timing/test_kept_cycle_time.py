"""A checked task's cycle time is kept in the user's cache folder and read back while the task, the cell's devices,
the processes and their charts are unchanged: an edit of any is estimated anew (on a user library outside the
package), a damaged kept file is estimated again, and a warm check generates no code (tests/test_startup.py)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import plugnproduce.timing.tasks
from plugnproduce import service
from plugnproduce.timing.cycle import CycleTime
from plugnproduce.timing.kept import kept_cycle_time

TIMED = Path(__file__).resolve().parents[1] / "data" / "libraries" / "timed-cell"


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    return Path(shutil.copytree(TIMED, tmp_path / "timed-cell"))


class Estimates:
    """``task_cycle_time``, counting the times it really estimates."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.count = 0
        self._estimate = plugnproduce.timing.tasks.task_cycle_time
        monkeypatch.setattr(plugnproduce.timing.tasks, "task_cycle_time", self)

    def __call__(self, *args: object) -> CycleTime | None:
        self.count += 1
        return self._estimate(*args)  # type: ignore[arg-type]


def _estimate(library: Path, cache: Path) -> CycleTime | None:
    cell_file = library / "cells" / "timed-cell.yaml"
    k = service.knowledge_for_cell(cell_file)
    cell, task = service.cell(cell_file, k), service.task(library / "tasks" / "pick-place-timed.yaml")
    return kept_cycle_time(task, cell, k, service.check(task, cell, k), cache)


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")


def test_an_unchanged_task_s_estimate_is_read_back(library: Path, tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    estimates = Estimates(monkeypatch)
    first = _estimate(library, tmp_path / "cache")
    again = _estimate(library, tmp_path / "cache")
    assert estimates.count == 1 and first is not None and again == first
    assert round(first.total, 2) == 7.70 and [s.command for s in first.steps] == ["move-to", "pick-and-place",
                                                                                   "move-to"]


@pytest.mark.parametrize("file, old, new", [
    ("tasks/pick-place-timed.yaml", "speed: 50", "speed: 25"),  # the task
    ("devices/tc-gripper.ttl", 'pnp:forRequest "Close" ; pnp:seconds 0.4', 'pnp:forRequest "Close" ; pnp:seconds 1.4'),
])
def test_an_edit_of_the_task_or_a_device_is_estimated_anew(library: Path, tmp_path: Path, file: str, old: str,
                                                            new: str, monkeypatch: pytest.MonkeyPatch) -> None:
    estimates = Estimates(monkeypatch)
    first = _estimate(library, tmp_path / "cache")
    _edit(library / file, old, new)
    edited = _estimate(library, tmp_path / "cache")
    assert estimates.count == 2 and first is not None and edited is not None and edited.total > first.total


def test_an_edit_of_a_device_state_chart_is_estimated_anew(library: Path, tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    estimates = Estimates(monkeypatch)
    _estimate(library, tmp_path / "cache")
    _edit(library / "devices" / "tc-gripper.scxml", 'delay="40ms"', 'delay="45ms"')
    _estimate(library, tmp_path / "cache")
    assert estimates.count == 2


def test_a_damaged_kept_estimate_is_estimated_again(library: Path, tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    estimates, cache = Estimates(monkeypatch), tmp_path / "cache"
    first = _estimate(library, cache)
    (kept,) = cache.glob("cycletime-*.pickle")
    kept.write_bytes(b"\x80not a pickle")
    assert _estimate(library, cache) == first and _estimate(library, cache) == first
    assert estimates.count == 2
