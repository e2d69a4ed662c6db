"""The executor runs the bin-picking task on the simulated cell over XIRP and UPnP, and stops safely on faults."""

from __future__ import annotations

import asyncio
import logging
from pathlib import Path

import pytest

from plugnproduce import controller, service
from plugnproduce.discovery import LiveCell
from plugnproduce.errors import PlugNProduceError
from plugnproduce.executor.journal import read_journal
from plugnproduce.executor.run import TaskRun
from plugnproduce.protocols import upnp
from plugnproduce.sim.cell import SimulatedCell, parse_faults
from plugnproduce.statechart.runtime.events import Event

TASK = service.builtin("tasks", "bin-picking.yaml")
CELL = service.builtin("cells", "bin-picking.yaml")


async def test_bin_picking_runs_to_the_end_and_the_journal_has_every_command_in_order(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.ERROR, logger="asyncio"):
        report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl")
    assert report.outcome == "succeeded", report.fault
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR] == []  # nothing went wrong unseen
    run = read_journal(report.journal)
    assert run.status == "succeeded"
    generated = service.generate(TASK, CELL).task.commands()
    for device in ("robot", "gripper", "sensor3d", "binpicking-pc"):  # each device gets its commands in task order
        expected = [(step, c.name) for step, d, c in generated if d == device and c.kind == "request"]
        sent = [(r["step"], r["command"]) for r in run.of_kind("command") if r["device"] == device]
        assert sent == expected, device
    assert {r["device"] for r in run.of_kind("event")} == {"robot", "gripper", "sensor3d", "binpicking-pc"}
    assert [r["step"] for r in run.of_kind("step")] == [1, 2, 3, 4, 5, 6]
    assert report.device_states["gripper"] == "open"


# fault spec -> (fault kind, what the report says)
FAULTS = {
    "gripper:drop-response:Close": ("timeout", "command Close: no answer within 2 s"),
    "gripper:error-response:Close": ("refused", "fault injected"),
    "gripper:disconnect:Close": ("lost", "command Close: request Close: device 'gripper' at "),  # names the command
    "gripper:drop-event:gripper_closed": ("timeout", "no event from gripper within 2 s"),
    "gripper:delay-event:gripper_closed:3": ("timeout", "no event from gripper within 2 s"),
    "gripper:duplicate-event:gripper_closed": ("anomaly", "twice"),
    "gripper:malformed-event": ("anomaly", "gripper"),
}


@pytest.mark.parametrize("spec", FAULTS)
async def test_each_fault_stops_the_run_safely_with_a_report(spec: str, tmp_path: Path) -> None:
    kind, text = FAULTS[spec]
    report = await controller.run_task(TASK, CELL, simulate=True, faults=spec, journal=tmp_path / "run.jsonl")
    assert report.outcome == "failed"
    fault = report.fault
    assert fault is not None and (fault.kind, fault.device) == (kind, "gripper")
    assert fault.step is not None and fault.command in {"bin-pick", "place"}
    assert text in fault.message
    assert fault.state in {"open", "closing", "closed"}
    run = read_journal(report.journal)
    kinds = [r["kind"] for r in run.records]
    assert run.status == "failed" and kinds[-1] == "end"
    first_fault = kinds.index("fault")
    assert "command" not in kinds[first_fault:], "no command may go out after the fault"
    assert run.end is not None and str(fault) == run.end["reason"]
    stops = {r["device"]: r for r in run.of_kind("stop")}
    assert set(stops) == {"robot", "gripper", "sensor3d", "binpicking-pc"}  # each device's answer and final state
    assert (stops["robot"]["request"], stops["robot"]["answer"]) == ("Halt", "accepted")
    assert stops["robot"]["state"] in {"home", "at_pose"} and run.end["device_states"]["robot"] == stops["robot"]["state"]
    assert kinds.index("stop") > first_fault
    for device, stop in stops.items():  # each record says where the device was left, as the report does
        assert set(stop) >= {"device", "state", "request", "answer"}
        assert stop["state"] == run.end["device_states"][device] == report.device_states[device], device
    assert {d: r["request"] for d, r in stops.items() if d != "robot"} == dict.fromkeys(stops.keys() - {"robot"})
    if kind == "lost":  # a device the controller cannot reach any more is said so, not called stopped
        assert stops["gripper"]["answer"].startswith("no state reported")
        assert stops["gripper"]["state"] in {"open", "closing", "closed"}  # as the controller last saw it
        assert run.safe_stop is not None and run.safe_stop.startswith("safe stop incomplete: gripper")
    else:
        assert run.safe_stop == "stopped safely"


async def test_an_unanswered_command_fails_the_run_at_the_step_that_sent_it(tmp_path: Path) -> None:
    """The robot's first MoveTo is carried out but never answered: the run does not end ``succeeded``."""
    report = await controller.run_task(TASK, CELL, simulate=True, faults="robot:drop-response:MoveTo",
                                    journal=tmp_path / "run.jsonl")
    assert report.outcome == "failed"
    fault = report.fault
    assert fault is not None
    assert (fault.kind, fault.step, fault.command, fault.device, fault.request, fault.state) == \
        ("timeout", 1, "bin-pick", "robot", "MoveTo", "home")
    run = read_journal(report.journal)
    kinds = [r["kind"] for r in run.records]
    assert "command" not in kinds[kinds.index("fault"):], "nothing may go out after the timeout"
    assert next(run.of_kind("stop"))["kind"] == "stop" and kinds[-1] == "end"


async def test_after_an_unanswered_close_the_fault_names_the_step_that_sent_it(tmp_path: Path) -> None:
    report = await controller.run_task(TASK, CELL, simulate=True, faults="gripper:drop-response:Close",
                                    journal=tmp_path / "run.jsonl")
    run = read_journal(report.journal)
    close = next(r for r in run.of_kind("command") if r["command"] == "Close")
    assert report.fault is not None and report.fault.request == "Close"
    assert (report.fault.step, report.fault.state) == (close["step"], "open")


async def test_a_device_unplugged_mid_task_stops_the_run(tmp_path: Path, taxonomy) -> None:
    cell = service.cell(CELL)
    generated = service.generate(TASK, cell).task
    network = upnp.private_network()
    async with SimulatedCell(cell, network=network) as sim, LiveCell(taxonomy, network=network) as live:
        devices = await controller.find_devices(live, [d.id for d in cell.devices], controller.SIMULATED_DISCOVERY_SECONDS)

        def unplug_after_first_gripper_event(record: dict[str, object]) -> None:
            if record["kind"] == "event" and record["device"] == "gripper":
                asyncio.get_running_loop().create_task(sim.unplug("gripper"))

        run = TaskRun(generated, devices, tmp_path / "run.jsonl", unplug_after_first_gripper_event)
        report = await run.run()
    assert report.outcome == "failed"
    assert report.fault is not None and (report.fault.kind, report.fault.device) == ("lost", "gripper")


async def test_an_operator_stop_ends_the_run_as_stopped(tmp_path: Path) -> None:
    def stop_at_step_2(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 2:
            runs[0].stop()

    runs: list[TaskRun] = []
    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=stop_at_step_2, started=runs.append)
    assert report.outcome == "stopped"
    run = read_journal(report.journal)
    step_2 = next(r for r in run.of_kind("step") if r["step"] == 2)
    assert report.fault is not None
    assert (report.fault.step, report.fault.command, report.fault.device, report.fault.message) == \
        (2, step_2["command"], None, "stopped by the operator")
    assert run.status == "stopped" and run.safe_stop == "stopped safely"
    assert {(r["device"], r["request"]) for r in run.of_kind("stop")} >= {("robot", "Halt")}


async def test_a_device_cable_pulled_while_it_has_nothing_to_do_stops_the_run(tmp_path: Path, taxonomy) -> None:
    """The gripper's connection drops once it has closed on a part: no gripper command is pending, and still the
    run stops at once, naming the gripper, the state it was last seen in and the loss."""
    cell = service.cell(CELL)
    generated = service.generate(TASK, cell).task
    network = upnp.private_network()
    async with SimulatedCell(cell, network=network) as sim, LiveCell(taxonomy, network=network) as live:
        devices = await controller.find_devices(live, [d.id for d in cell.devices], controller.SIMULATED_DISCOVERY_SECONDS)

        def pull_the_gripper_cable_once_closed(record: dict[str, object]) -> None:
            if record["kind"] == "event" and record["event"] == "gripper_closed" and record["step"] == 1:
                asyncio.get_running_loop().create_task(sim.devices["gripper"].drop_connections())

        report = await TaskRun(generated, devices, tmp_path / "run.jsonl", pull_the_gripper_cable_once_closed).run()
    assert report.outcome == "failed"
    fault = report.fault
    assert fault is not None
    assert (fault.kind, fault.device, fault.state, fault.request, fault.step, fault.command) == \
        ("lost", "gripper", "closed", None, 1, "bin-pick")
    assert "connection lost" in fault.message
    run = read_journal(report.journal)
    assert "Open" not in [r["command"] for r in run.of_kind("command")]
    gripper = next(r for r in run.of_kind("stop") if r["device"] == "gripper")
    assert gripper["answer"].startswith("no state reported") and gripper["state"] == "closed"


# a fault of the robot's own safe stop -> what its stop record says
STOP_FAULTS = {
    "robot:drop-response:Halt": "no answer within 5 s",
    "robot:error-response:Halt": "refused: ",
    "robot:disconnect:Halt": "refused: ",
}


@pytest.mark.parametrize("spec", STOP_FAULTS)
async def test_a_safe_stop_the_robot_does_not_accept_is_reported_as_incomplete(spec: str, tmp_path: Path) -> None:
    report = await controller.run_task(TASK, CELL, simulate=True, faults=f"gripper:error-response:Close,{spec}",
                                    journal=tmp_path / "run.jsonl")
    assert report.outcome == "failed" and report.fault is not None and report.fault.kind == "refused"
    run = read_journal(report.journal)
    robot = next(r for r in run.of_kind("stop") if r["device"] == "robot")
    assert robot["request"] == "Halt" and robot["answer"].startswith(STOP_FAULTS[spec])
    assert robot["state"] in {"home", "at_pose"} and report.device_states["robot"] == robot["state"]
    assert run.safe_stop is not None and run.safe_stop.startswith("safe stop incomplete: robot (Halt: ")


async def test_a_device_gone_before_the_run_stops_the_devices_already_reached(tmp_path: Path, taxonomy) -> None:
    """The gripper is unplugged before the run: the run fails before its first step and stops the robot, reached
    already; the robot does not report its state either, so its record keeps the state its chart starts in."""
    cell = service.cell(CELL)
    generated = service.generate(TASK, cell).task
    network = upnp.private_network()
    faults = parse_faults("robot:drop-response:state", cell.devices)
    async with SimulatedCell(cell, network=network, faults=faults) as sim, LiveCell(taxonomy, network=network) as live:
        devices = await controller.find_devices(live, [d.id for d in cell.devices], controller.SIMULATED_DISCOVERY_SECONDS)
        await sim.unplug("gripper")
        report = await TaskRun(generated, devices, tmp_path / "run.jsonl").run()
    assert report.outcome == "failed"
    fault = report.fault
    assert fault is not None and (fault.kind, fault.device, fault.step) == ("lost", "gripper", None)
    assert fault.message.startswith("cannot connect")
    run = read_journal(report.journal)
    assert [(r["device"], r["state"], r["request"]) for r in run.of_kind("stop")] == [("robot", "home", None)]
    assert next(run.of_kind("stop"))["answer"].startswith("no state reported")


async def test_the_journal_says_what_each_event_brought_and_where_each_value_went(tmp_path: Path) -> None:
    """One part in a simulated bin: the bin-picking PC's PartLocalized is journalled at its step with the pose it
    found, that pose as a value the step produced, and the robot's next MoveTo as the step that uses it."""
    task = service.builtin("tasks", "bin-picking-until-empty.yaml")
    report = await controller.run_task(task, CELL, simulate=True, bin_parts=1, bin_seed=1, journal=tmp_path / "run.jsonl")
    assert report.outcome == "succeeded", report.fault
    run = read_journal(report.journal)
    assert all(set(r) >= {"step", "device", "event", "params"} for r in run.of_kind("event"))
    found = next(r for r in run.of_kind("event") if r["event"] == "PartLocalized")
    pose = found["params"]["part_pose"]
    assert (found["step"], found["device"], found["params"]["outcome"]) == (1, "binpicking-pc", "PartFound")
    values = [{k: v for k, v in r.items() if k not in ("seq", "t", "kind")} for r in run.of_kind("value")]
    assert values[:3] == [
        {"value": "localize.part_pose", "produced": pose, "step": 1, "device": "binpicking-pc"},
        {"value": "outcome", "produced": "PartFound", "step": 1, "device": "binpicking-pc"},
        {"value": "localize.part_pose", "used": pose, "step": 2, "device": "robot", "parameter": "pick_pose"},
    ]
    move = next(r for r in run.of_kind("command") if r["step"] == 2)
    assert (move["device"], move["command"], move["params"]["TargetPose"]) == ("robot", "MoveTo", pose)


async def test_an_event_the_task_does_not_wait_for_stops_the_run_naming_it(tmp_path: Path, taxonomy) -> None:
    """While the robot moves to the part, the gripper reports an event nothing waits for (its name has dots,
    as XIRP names may): the run stops, naming the gripper, the state it was in and the whole event name."""
    cell = service.cell(CELL)
    generated = service.generate(TASK, cell).task
    network = upnp.private_network()
    async with SimulatedCell(cell, network=network) as sim, LiveCell(taxonomy, network=network) as live:
        devices = await controller.find_devices(live, [d.id for d in cell.devices], controller.SIMULATED_DISCOVERY_SECONDS)

        def gripper_speaks_up_during_the_first_move(record: dict[str, object]) -> None:
            if record["kind"] == "command" and record["command"] == "MoveTo" and record["step"] == 1:
                sim.devices["gripper"].send(Event("xirp.event.status.jaw.changed"), None, "xirp")

        report = await TaskRun(generated, devices, tmp_path / "run.jsonl", gripper_speaks_up_during_the_first_move
                               ).run()
    assert report.outcome == "failed"
    fault = report.fault
    assert fault is not None
    assert (fault.kind, fault.device, fault.state, fault.step, fault.command, fault.request) == \
        ("unexpected", "gripper", "open", 1, "bin-pick", None)
    assert fault.message == "event status.jaw.changed is not what the task waits for now"
    run = read_journal(report.journal)
    assert [(r["fault"], r["first"]) for r in run.of_kind("fault")] == [("unexpected", True)]


async def test_the_controller_sends_only_requests_to_devices_of_the_cell(tmp_path: Path) -> None:
    """Whatever a task chart asks, only a request to a device of the cell goes out: an event, an internal name or
    a request to another device is refused before anything is journalled or sent."""
    runs: list[TaskRun] = []
    refusals: list[str] = []

    def ask_the_odd_things_at_step_1(record: dict[str, object]) -> None:
        if record["kind"] == "step" and record["step"] == 1:
            for name, target in (("xirp.request.MoveTo", "stranger"), ("xirp.event.motion_done", "robot"),
                                 ("motion.done", "robot")):
                try:
                    runs[0].send(Event(name), target, "xirp")
                except PlugNProduceError as exc:
                    refusals.append(str(exc))
            runs[0].stop("asked")

    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=ask_the_odd_things_at_step_1, started=runs.append)
    assert refusals == [
        "cannot send 'xirp.request.MoveTo' to 'stranger': not a request to a device of the cell",
        "cannot send 'xirp.event.motion_done' to 'robot': not a request to a device of the cell",
        "cannot send 'motion.done' to 'robot': not a request to a device of the cell",
    ]
    assert report.outcome == "stopped"
    assert list(read_journal(report.journal).of_kind("command")) == []
