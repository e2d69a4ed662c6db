"""Once a command goes unanswered nothing more is sent but the safe stop, and the journal says only what is known."""

from __future__ import annotations

from pathlib import Path

from plugnproduce import controller, service
from plugnproduce.executor.journal import describe, read_journal

TASK = service.builtin("tasks", "bin-picking.yaml")
CELL = service.builtin("cells", "bin-picking.yaml")


async def test_no_command_goes_out_after_an_unanswered_close(tmp_path: Path) -> None:
    report = await controller.run_task(TASK, CELL, simulate=True, faults="gripper:drop-response:Close",
                                    journal=tmp_path / "run.jsonl")
    assert report.outcome == "failed" and report.fault is not None
    run = read_journal(report.journal)
    commands = [(r["device"], r["command"]) for r in run.of_kind("command")]
    assert commands[-1] == ("gripper", "Close")  # the first Close, at step 1; nothing after it
    assert commands.count(("gripper", "Close")) == 1
    assert [r["request"] for r in run.of_kind("stop") if r["request"]] == ["Halt"]  # only the safe stop


async def test_an_unanswered_close_is_reported_at_its_step_with_what_is_known(tmp_path: Path) -> None:
    report = await controller.run_task(TASK, CELL, simulate=True, faults="gripper:drop-response:Close",
                                    journal=tmp_path / "run.jsonl")
    fault = report.fault
    assert fault is not None and (fault.kind, fault.step, fault.request, fault.state) == ("timeout", 1, "Close", "open")
    assert "it was sent, and whether gripper carries it out is not known" in fault.message
    run = read_journal(report.journal)
    assert [r["step"] for r in run.of_kind("step")] == [1]  # the run never went on to step 2 or 3
    gripper_states = [r["state"] for r in run.of_kind("state") if r["device"] == "gripper"]
    assert gripper_states == ["open"]  # never "closing": nothing confirmed that Close was taken
    (ignored,) = [r for r in run.of_kind("event") if r.get("ignored")]
    assert (ignored["device"], ignored["event"]) == ("gripper", "gripper_closed")
    assert describe(ignored).startswith("← gripper: gripper_closed (not acted on: ")
    stop = next(r for r in run.of_kind("stop") if r["device"] == "gripper")
    assert describe(stop) == f"stop gripper: reports state {stop['state']}, which takes no stop request"
