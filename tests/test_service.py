"""The use cases both faces share: generation as a result, and the one path that starts a run."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from plugnproduce import controller, service
from plugnproduce.codegen import outputs
from plugnproduce.description.model import Task

TASK = service.builtin("tasks", "bin-picking.yaml")
CELL = service.builtin("cells", "bin-picking.yaml")


def _implausible() -> Task:
    """The bin-picking task's place step alone: nothing is held, so it is not plausible."""
    task = service.task(TASK)
    place = next(s for s in task.steps if s.command == "place")
    return dataclasses.replace(task, name="place-first", steps=(dataclasses.replace(place, index=1),), repeat=1)


def test_generation_of_an_implausible_task_is_a_result_without_charts() -> None:
    result = service.generation(_implausible(), CELL)
    assert result.check.plausible is False and result.check.problems
    assert result.generated is None and result.charts == []
    with pytest.raises(service.ImplausibleTask):
        service.generate(_implausible(), CELL)


def test_generation_of_a_plausible_task_has_the_charts_generate_writes() -> None:
    result = service.generation(TASK, CELL)
    assert result.check.plausible and result.generated is not None
    assert [c.name for c in result.charts] == [c.name for c in service.generate(TASK, CELL).charts]


def test_generation_of_a_program_verification_refutes_is_a_result_without_charts(tmp_path: Path) -> None:
    from plugnproduce.verification import Budget
    from tests.verification.test_verify import napping_gripper, seeded_cell

    result = service.generation(TASK, seeded_cell(tmp_path, napping_gripper()), verify=Budget())
    assert result.check.plausible and result.charts == []
    assert result.verification is not None and result.verification.verdict == "refuted"
    assert "device gripper in state standby refuses xirp.request.Close" in result.verification.problem
    with pytest.raises(service.Unverified):
        service.generate(TASK, seeded_cell(tmp_path / "again", napping_gripper()), verify=Budget())


def test_a_run_is_planned_without_the_closed_world_chart_or_device_programs(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    def refuse(*_: object, **__: object) -> None:
        raise AssertionError("a run generated a chart it does not need")

    expected = service.generate(TASK, CELL).task.task_chart()
    monkeypatch.setattr(outputs, "closed_world_chart", refuse)
    monkeypatch.setattr(outputs, "device_program", refuse)
    monkeypatch.setattr(outputs, "all_charts", refuse)
    planned = service.plan_run(TASK, CELL)
    assert planned.task_chart() == expected
    run = controller.start_run(planned, service.cell(CELL), tmp_path / "run.jsonl")
    assert run.journal_path == tmp_path / "run.jsonl" and run.cell.name == service.cell(CELL).name


def test_planning_an_implausible_run_raises_before_anything_runs() -> None:
    with pytest.raises(service.ImplausibleTask):
        service.plan_run(_implausible(), CELL)
