"""The repairs of a long task make long-lived results (repaired tasks, their checks and programs), not cyclic
garbage: Python's cyclic collector is paused while they are made, estimated and written, and on again afterwards,
also when they fail."""

from __future__ import annotations

import gc
from collections.abc import Callable

import pytest

import plugnproduce.description.taskfile
import plugnproduce.reasoning
import plugnproduce.timing.tasks
from plugnproduce import service
from plugnproduce.description.model import Cell
from tests.reasoning.conftest import TASKS

INVALID = TASKS / "bin-picking-invalid.yaml"


def _watched(real: Callable[..., object], seen: list[bool]) -> Callable[..., object]:
    def watched(*args: object, **kwargs: object) -> object:
        seen.append(gc.isenabled())
        return real(*args, **kwargs)
    return watched


def test_repairs_and_their_cycle_times_run_with_the_collector_paused(cell: Cell,
                                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    assert gc.isenabled()
    assessing: list[bool] = []
    estimating: list[bool] = []
    monkeypatch.setattr(plugnproduce.reasoning, "assess", _watched(plugnproduce.reasoning.assess, assessing))
    monkeypatch.setattr(plugnproduce.timing.tasks, "estimate_task",
                        _watched(plugnproduce.timing.tasks.estimate_task, estimating))
    repairs = service.assessed_repairs(INVALID, cell)
    assert gc.isenabled()
    times = service.repair_cycle_times(repairs, cell)
    assert gc.isenabled()
    assert repairs and assessing and not any(assessing)
    assert estimating and not any(estimating) and any(t is not None for t in times)


def test_a_repaired_task_is_written_with_the_collector_paused(cell: Cell, monkeypatch: pytest.MonkeyPatch) -> None:
    writing: list[bool] = []
    repaired = service.assessed_repairs(INVALID, cell)[0].repair.task
    monkeypatch.setattr(plugnproduce.description.taskfile, "task_to_yaml",
                        _watched(plugnproduce.description.taskfile.task_to_yaml, writing))
    text = service.task_text(repaired)
    assert writing == [False] and gc.isenabled()
    assert service.task_text(repaired) == text and "steps:" in text


def test_a_repair_that_fails_turns_the_collector_on_again(cell: Cell, monkeypatch: pytest.MonkeyPatch) -> None:
    def failing(*args: object, **kwargs: object) -> object:
        raise RuntimeError("the assessment failed")

    monkeypatch.setattr(plugnproduce.reasoning, "assess", failing)
    with pytest.raises(RuntimeError, match="the assessment failed"):
        service.assessed_repairs(INVALID, cell)
    assert gc.isenabled()
