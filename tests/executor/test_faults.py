"""Fault handling as the chart and the journal see it: a fault is told to the task chart,
which leaves for ``failed`` at once (it does not wait for its own timeouts), the first fault
is the run's, and only a device of the cell can be lost."""

from __future__ import annotations

from pathlib import Path

from plugnproduce import service
from plugnproduce.codegen import FAILED
from plugnproduce.executor.journal import read_journal
from plugnproduce.executor.run import TaskRun

TASK = service.builtin("tasks", "bin-picking.yaml")
CELL = service.builtin("cells", "bin-picking.yaml")


async def test_a_stop_is_told_to_the_chart_which_ends_in_failed_with_one_fault(tmp_path: Path) -> None:
    runs: list[TaskRun] = []

    def stop_twice_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            runs[0].stop("first stop")
            runs[0].stop("second stop")

    report = await service.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=stop_twice_at_step_2, started=runs.append)
    assert runs[0].interpreter.final_state == FAILED
    assert report.fault is not None and report.fault.message == "first stop" and report.fault.kind == "stopped"
    run = read_journal(report.journal)
    faults = [(r["message"], r["first"]) for r in run.of_kind("fault")]
    assert faults == [("first stop", True), ("second stop", False)]  # the chart's own timers never fired
    kinds = [r["kind"] for r in run.records]
    assert kinds[-1] == "end" and "command" not in kinds[kinds.index("fault"):]
    assert run.end is not None and run.end["outcome"] == "stopped" and run.end["reason"].endswith("first stop")


async def test_a_device_outside_the_cell_leaving_does_not_stop_the_run(tmp_path: Path) -> None:
    runs: list[TaskRun] = []

    def stranger_leaves_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            runs[0].device_lost("stranger", "byebye")

    report = await service.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=stranger_leaves_at_step_2, started=runs.append)
    assert report.outcome == "succeeded" and report.fault is None
    run = read_journal(report.journal)
    assert list(run.of_kind("fault")) == [] and list(run.of_kind("stop")) == []


async def test_a_device_of_the_cell_leaving_stops_the_run_naming_it(tmp_path: Path) -> None:
    runs: list[TaskRun] = []

    def gripper_leaves_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            runs[0].device_lost("gripper", "its byebye was confirmed")

    report = await service.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=gripper_leaves_at_step_2, started=runs.append)
    assert report.outcome == "failed" and runs[0].interpreter.final_state == FAILED
    assert report.fault is not None
    assert (report.fault.kind, report.fault.device, report.fault.step, report.fault.message) == \
        ("lost", "gripper", 2, "its byebye was confirmed")
