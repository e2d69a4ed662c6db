"""Fault handling as the chart and the journal see it: a fault is told to the task chart,
which leaves for ``failed`` at once (it does not wait for its own timeouts), the first fault
is the run's, and only a device of the cell can be lost."""

from __future__ import annotations

import shutil
from pathlib import Path

from plugnproduce import controller, service
from plugnproduce.chartnames import FAILED
from plugnproduce.executor.journal import read_journal
from plugnproduce.executor.run import TaskRun
from tests.conftest import edit

TASK = service.builtin("tasks", "bin-picking.yaml")
CELL = service.builtin("cells", "bin-picking.yaml")


async def test_a_stop_is_told_to_the_chart_which_ends_in_failed_with_one_fault(tmp_path: Path) -> None:
    runs: list[TaskRun] = []

    def stop_twice_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            runs[0].stop("first stop")
            runs[0].stop("second stop")

    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
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

    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=stranger_leaves_at_step_2, started=runs.append)
    assert report.outcome == "succeeded" and report.fault is None
    run = read_journal(report.journal)
    assert list(run.of_kind("fault")) == [] and list(run.of_kind("stop")) == []


async def test_a_device_of_the_cell_leaving_stops_the_run_naming_it(tmp_path: Path) -> None:
    runs: list[TaskRun] = []

    def gripper_leaves_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            runs[0].device_lost("gripper", "its byebye was confirmed")

    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=gripper_leaves_at_step_2, started=runs.append)
    assert report.outcome == "failed" and runs[0].interpreter.final_state == FAILED
    assert report.fault is not None
    assert (report.fault.kind, report.fault.device, report.fault.step, report.fault.message) == \
        ("lost", "gripper", 2, "its byebye was confirmed")


class NotedBounds:
    """A device link that notes the time bound of every state query and request made through it."""

    def __init__(self, device: str, link: object, noted: list[tuple[str, str, float]]) -> None:
        self._device, self._link, self._noted = device, link, noted

    async def request(self, name: str, params: dict[str, object], timeout: float) -> None:
        self._noted.append((self._device, name, timeout))
        await self._link.request(name, params, timeout)  # type: ignore[attr-defined]

    async def state(self, timeout: float) -> str:
        self._noted.append((self._device, "state", timeout))
        return await self._link.state(timeout)  # type: ignore[attr-defined,no-any-return]

    def __getattr__(self, name: str) -> object:
        return getattr(self._link, name)


async def test_a_safe_stop_waits_at_most_five_seconds_for_each_answer_even_from_a_slow_device(tmp_path: Path) -> None:
    """The robot's commands may take 30 s, but a stop asks it (and each device) with at most 5 s, or the
    device's own shorter bound: an operator's stop is never held up by a device that does not answer."""
    devices = tmp_path / "devices"
    devices.mkdir()
    for name in ("robot", "gripper", "sensor3d", "binpicking-pc"):
        for suffix in (".ttl", ".scxml"):
            shutil.copy(service.builtin("devices", name + suffix), devices)
    edit(devices / "robot.ttl", "pnp:commandTimeout 5.0", "pnp:commandTimeout 30.0")
    cell = tmp_path / "slow-robot.yaml"
    cell.write_text("cell: slow-robot\ndevices:\n" + "".join(f"  - devices/{n}.ttl\n" for n in
                                                              ("robot", "gripper", "sensor3d", "binpicking-pc")))
    runs: list[TaskRun] = []
    noted: list[tuple[str, str, float]] = []

    def stop_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            links = runs[0]._links
            for device, link in list(links.items()):
                links[device] = NotedBounds(device, link, noted)  # type: ignore[assignment]
            runs[0].stop("operator stop")

    report = await controller.run_task(TASK, cell, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=stop_at_step_2, started=runs.append)
    assert report.outcome == "stopped"
    stop_requests = {device for device, what, _ in noted if what != "state"}
    assert "robot" in stop_requests, "the robot was sent its safe-stop request"
    # each answer waited for at most 5 s, or the device's own shorter bound (the gripper's 2 s, the sensor's 3 s)
    assert {(device, timeout) for device, _, timeout in noted} == {("robot", 5.0), ("gripper", 2.0),
                                                                   ("sensor3d", 3.0), ("binpicking-pc", 5.0)}
    assert {device for device, what, _ in noted if what == "state"} == {"robot", "gripper", "sensor3d",
                                                                       "binpicking-pc"}
