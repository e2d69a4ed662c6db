"""Simulated devices run their own charts behind real XIRP and UPnP servers on loopback."""

from __future__ import annotations

import pytest

from plugnproduce import controller, service
from plugnproduce.discovery import LiveCell
from plugnproduce.errors import ProtocolError, ProtocolTimeout
from plugnproduce.protocols import upnp, xirp
from plugnproduce.sim.cell import FaultSpecError, SimulatedCell, parse_faults
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT


def device(name: str):
    return service.cell(service.builtin("cells", "bin-picking.yaml")).device(name) if name != "conveyor" else \
        next(d for d in service.catalogue() if d.id == name)


async def next_change_of(live: LiveCell, kind: str, device: str):
    """The next change of this kind for this device (earlier ones, e.g. the plugs at start, are passed over)."""
    while True:
        change = await live.next_change(WAIT)
        if (change.kind, change.device) == (kind, device):
            return change


@pytest.fixture
def network() -> upnp.SsdpNetwork:
    return upnp.private_network()


async def test_gripper_closes_on_request_and_reports_it_over_xirp(network) -> None:
    async with SimulatedDevice(device("gripper"), network=network) as gripper:
        async with await xirp.XirpClient.connect_endpoint(gripper.endpoint) as client:
            assert client.device == "gripper"
            await client.request("Close", {"GripForce": 40.0})
            event = await client.next_event(WAIT)
            assert event.name == "gripper_closed"
            assert gripper.state == "closed"


async def test_devices_report_their_state_over_xirp_and_upnp(network) -> None:
    async with SimulatedDevice(device("gripper"), network=network) as gripper, \
            SimulatedDevice(device("sensor3d"), network=network) as sensor:
        async with await xirp.XirpClient.connect_endpoint(gripper.endpoint) as client:
            assert await client.state() == "open"
            await client.request("Close", {"GripForce": 40.0})
            await client.next_event(WAIT)
            assert await client.state() == "closed"
        client2 = await upnp.UpnpDeviceClient.connect(sensor.endpoint, "127.0.0.1")
        try:
            answer = await client2.invoke(upnp.STATE_ACTION, {})
        finally:
            await client2.close()
        assert answer == {upnp.STATE_ARGUMENT: sensor.state}


async def test_a_moving_robot_takes_its_safe_stop_and_holds_where_it_is(network) -> None:
    robot_description = device("robot")
    assert {(t.source, t.target) for t in robot_description.stops} >= {("moving", "at_pose"), ("home", "home")}
    async with SimulatedDevice(robot_description, network=network) as robot:
        async with await xirp.XirpClient.connect_endpoint(robot.endpoint) as client:
            await client.request("MoveTo", {"TargetPose": [0.4, 0.1, 0.2, 0, 180, 0], "Speed": 50.0})
            assert await client.state() == "moving"
            await client.request("Halt")
            assert await client.state() == "at_pose"
            with pytest.raises(ProtocolTimeout):  # the motion it was making never reports done
                await client.next_event(1.0)


async def test_a_request_the_chart_does_not_wait_for_is_refused_and_changes_nothing(network) -> None:
    async with SimulatedDevice(device("gripper"), network=network) as gripper:
        async with await xirp.XirpClient.connect_endpoint(gripper.endpoint) as client:
            with pytest.raises(xirp.RemoteFailure) as refused:
                await client.request("Open")
            assert refused.value.code == xirp.NOT_ACCEPTED
            assert "gripper is open" in refused.value.text
            assert gripper.state == "open"


async def test_device_serves_its_description_with_the_endpoint_it_listens_on(network) -> None:
    async with SimulatedDevice(device("gripper"), network=network) as gripper:
        async with await xirp.XirpClient.connect_endpoint(gripper.endpoint) as client:
            files = await client.describe()
        assert f'pnp:endpoint "{gripper.endpoint}"' in files.description
    assert 'initial="open"' in files.chart


async def test_upnp_sensor_captures_on_an_action_and_reports_by_gena(network) -> None:
    async with SimulatedDevice(device("sensor3d"), network=network) as sensor:
        async with await upnp.UpnpDeviceClient.connect(sensor.endpoint, "127.0.0.1") as client:
            await client.subscribe()
            assert set(client.actions) >= {"Capture"}
            await client.call("Capture", Exposure="8")
            change = await client.next_change(WAIT)
            assert change.variable == "CaptureDone" and change.value == 1


async def test_the_simulated_cell_is_discovered_and_follows_plug_and_unplug(network, taxonomy) -> None:
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    async with SimulatedCell(cell, catalogue=service.catalogue(), network=network) as sim, \
            LiveCell(taxonomy, network=network) as live:
        found = await controller.find_devices(live, ["robot", "gripper", "sensor3d", "binpicking-pc"], WAIT)
        assert found.device("gripper").endpoint == sim.devices["gripper"].endpoint
        assert "pick" in service.capabilities(live.cell).commands()
        await sim.unplug("gripper")
        change = await next_change_of(live, "unplug", "gripper")
        assert "pick" not in service.capabilities(change.cell).commands()
        await sim.plug("gripper")
        change = await next_change_of(live, "plug", "gripper")
        assert "pick" in service.capabilities(change.cell).commands()
        with pytest.raises(ProtocolError, match="plugged in already"):
            await sim.plug("gripper")


def test_fault_specs_are_read_or_refused_with_the_reason() -> None:
    devices = service.cell(service.builtin("cells", "bin-picking.yaml")).devices
    faults = parse_faults("gripper:drop-response:Close, robot:delay-event:arrived:3", devices)
    assert [(f.kind, f.name) for f in faults["gripper"].rules] == [(xirp.FaultKind.DROP_RESPONSE, "Close")]
    assert faults["robot"].rules[0].delay == 3.0
    for spec, reason in [("tool:disconnect", r"unknown device 'tool' of the cell \(known: binpicking-pc, gripper,"),
                         ("griper:disconnect", r"unknown device 'griper' of the cell; did you mean gripper\?"),
                         ("gripper:explode", "unknown kind"),
                         ("sensor3d:disconnect", "speaks upnp"), ("gripper", "expected DEVICE:KIND")]:
        with pytest.raises(FaultSpecError, match=reason):
            parse_faults(spec, devices)


@pytest.mark.parametrize("seconds", ["nan", "inf", "-1", "-0.5", "1e400", "3601", "", "٣"])
def test_issue_24_fault_seconds_that_are_not_finite_or_negative_are_refused(seconds: str) -> None:
    # robot:delay-event::nan was accepted
    devices = service.cell(service.builtin("cells", "bin-picking.yaml")).devices
    with pytest.raises(FaultSpecError, match=r"SECONDS must be a number from 0 to 3600; found"):
        parse_faults(f"robot:delay-event::{seconds}", devices)


def test_issue_24_a_run_with_nan_fault_seconds_is_bad_input_in_one_line() -> None:
    from typer.testing import CliRunner

    from plugnproduce.cli import app

    task = str(service.builtin("tasks", "pick-and-place.yaml"))
    result = CliRunner().invoke(app, ["run", task, "--sim", "--faults", "robot:delay-event::nan"])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [
        "error: --faults 'robot:delay-event::nan': SECONDS must be a number from 0 to 3600; found 'nan'"]
