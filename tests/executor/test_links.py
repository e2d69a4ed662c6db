"""The controller's link to one device, per protocol, against one simulated device on loopback (no cell, no run):
what a request sends, which device an event, a lost connection or an anomaly is reported for, and the state asked."""

from __future__ import annotations

import asyncio
import dataclasses
import math
from collections.abc import AsyncIterator, Mapping
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.description.model import DeviceDescription
from plugnproduce.errors import ProtocolError, ProtocolTimeout
from plugnproduce.executor import links
from plugnproduce.executor.links import DeviceLink, UpnpLink, open_link, query_report, query_state
from plugnproduce.protocols import upnp, xirp
from plugnproduce.sim.bin import SimulatedBin
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT

BIN_PICKING = service.builtin("cells", "bin-picking.yaml")
MIXED = service.builtin("cells", "mixed.yaml")
SHORT_ARMS = Path(__file__).parents[1] / "data" / "libraries" / "short-arm" / "cells" / "short-arms.yaml"
"""A library's arm over XIRP, UPnP and OPC UA, each reporting the pose it was left at with its state."""
GUIDED = [0.35, 0.15, 0.22, 0.0, 180.0, 45.0]
SHORT = 0.5
"""The timeout a test gives one request; its device's own command timeout is far longer (LONG)."""
LONG = 3600.0


def device(cell: Path, name: str) -> DeviceDescription:
    return service.cell(cell).device(name)


class Heard:
    """What a link reported through its three callbacks, in order, each with the device it named."""

    def __init__(self) -> None:
        self.events: asyncio.Queue[tuple[str, str, Mapping[str, Any]]] = asyncio.Queue()
        self.lost: asyncio.Queue[tuple[str, str]] = asyncio.Queue()
        self.anomalies: asyncio.Queue[tuple[str, str]] = asyncio.Queue()

    async def open(self, live: DeviceDescription) -> DeviceLink:
        return await open_link(live, lambda d, name, params: self.events.put_nowait((d, name, params)),
                               lambda d, reason: self.lost.put_nowait((d, reason)),
                               lambda d, what: self.anomalies.put_nowait((d, what)))


@asynccontextmanager
async def simulated(described: DeviceDescription, **options: Any) -> AsyncIterator[tuple[SimulatedDevice,
                                                                                         DeviceDescription]]:
    """One simulated device on a private SSDP network, and its description pointing at where it listens."""
    async with SimulatedDevice(described, network=upnp.private_network(), **options) as sim:
        yield sim, dataclasses.replace(described, endpoint=sim.endpoint, command_timeout=WAIT)


async def test_an_xirp_link_sends_the_request_and_reports_the_event_for_its_device() -> None:
    heard = Heard()
    async with simulated(device(BIN_PICKING, "gripper")) as (sim, live):
        link = await heard.open(live)
        try:
            assert await link.state(WAIT) == "open"
            await link.request("Close", {"GripForce": 40}, WAIT)
            assert await asyncio.wait_for(heard.events.get(), WAIT) == ("gripper", "gripper_closed", {})
            assert await link.state(WAIT) == "closed" == sim.state
        finally:
            await link.close()
    assert heard.lost.empty() and heard.anomalies.empty()  # a polite close is no lost connection


async def test_an_xirp_request_the_device_refuses_raises_with_its_reason() -> None:
    async with simulated(device(BIN_PICKING, "gripper")) as (_, live):
        link = await Heard().open(live)
        try:
            with pytest.raises(ProtocolError, match="gripper is open; it does not accept Open now"):
                await link.request("Open", {}, WAIT)
        finally:
            await link.close()


async def test_a_pulled_xirp_cable_is_reported_as_lost_for_its_device() -> None:
    heard = Heard()
    async with simulated(device(BIN_PICKING, "gripper")) as (sim, live):
        link = await heard.open(live)
        try:
            assert await sim.drop_connections() == 1
            who, reason = await asyncio.wait_for(heard.lost.get(), WAIT)
        finally:
            await link.close()
    assert who == "gripper" and "connection" in reason


async def test_a_duplicated_xirp_event_is_reported_as_an_anomaly_of_its_device() -> None:
    heard = Heard()
    faults = xirp.Faults()
    faults.add(xirp.FaultKind.DUPLICATE_EVENT, "gripper_closed")
    async with simulated(device(BIN_PICKING, "gripper"), faults=faults) as (_, live):
        link = await heard.open(live)
        try:
            await link.request("Close", {"GripForce": 40}, WAIT)
            who, what = await asyncio.wait_for(heard.anomalies.get(), WAIT)
        finally:
            await link.close()
    assert who == "gripper" and "gripper_closed" in what
    assert (await heard.events.get())[:2] == ("gripper", "gripper_closed") and heard.events.empty()


async def test_a_upnp_link_sends_the_action_and_reports_the_event_with_the_values_it_carries() -> None:
    heard = Heard()
    parts = SimulatedBin(3, seed=5)
    top = max(SimulatedBin(3, seed=5).parts, key=lambda p: p.pose[2])
    async with simulated(device(BIN_PICKING, "binpicking-pc"), bin=parts) as (_, live):
        link = await heard.open(live)
        try:
            assert isinstance(link, UpnpLink)
            assert await link.state(WAIT) == "ready"
            await link.request("Localize", {"PartType": "bracket"}, WAIT)
            event = await asyncio.wait_for(heard.events.get(), WAIT)
            assert await link.state(WAIT) == "localized"
        finally:
            await link.close()
    assert event == ("binpicking-pc", "PartLocalized",
                     {"outcome": "PartFound", "part_pose": top.pose, "part_type": "bracket"})
    assert heard.events.empty()  # the values came with the event, not as events of their own


async def test_a_upnp_link_writes_a_pose_as_the_wire_format_says() -> None:
    async with simulated(device(BIN_PICKING, "binpicking-pc")) as (_, live):
        received: list[dict[str, Any]] = []

        async def handler(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
            received.append({"action": action, **arguments})
            return {upnp.STATE_ARGUMENT: ""} if action == upnp.STATE_ACTION else {"Result": "accepted"}

        spec = upnp.with_state_query(upnp.service_spec_from_chart_events({"MoveTo": ["TargetPose", "Speed"]}, []))
        async with upnp.UpnpDeviceServer("scara", "Recording robot", upnp.device_type_for("Robot"), spec, handler,
                                         network=upnp.private_network()) as server:
            recording = dataclasses.replace(live, id="scara", endpoint=server.location or "")
            link = await Heard().open(recording)
            try:
                await link.request("MoveTo", {"TargetPose": [0.4, 0.1, 0.05, 0, 180, 0], "Speed": 50}, WAIT)
                with pytest.raises(ProtocolError, match=f"^device scara: {upnp.STATE_ACTION} answered no {upnp.STATE_ARGUMENT}$"):
                    await link.state(WAIT)
            finally:
                await link.close()
    assert received == [{"action": "MoveTo", "TargetPose": "0.4 0.1 0.05 0 180 0", "Speed": "50"},
                        {"action": upnp.STATE_ACTION}]


async def test_an_opc_ua_method_answer_is_reported_as_the_event_it_stands_for() -> None:
    heard = Heard()
    async with simulated(device(MIXED, "binpicking-pc-ua")) as (_, live):
        link = await heard.open(live)
        try:
            assert await link.state(WAIT) == "ready"
            await link.request("Localize", {"PartType": "bracket"}, WAIT)
            event = heard.events.get_nowait()  # the method's output arguments: there when the call returns
            assert await link.state(WAIT) == "localized"
        finally:
            await link.close()
    assert event[:2] == ("binpicking-pc-ua", "PartLocalized")
    assert event[2]["part_pose"] == [0.4, 0.1, 0.05, 0.0, 180.0, 0.0]
    assert heard.lost.empty() and heard.anomalies.empty()


async def test_an_opc_ua_link_reports_the_event_an_anomaly_and_the_lost_session_for_its_device() -> None:
    heard = Heard()
    async with simulated(device(MIXED, "screwdriver-ua")) as (sim, live):
        link = await heard.open(live)
        try:
            await link.request("Start", {"Torque": 3.0}, WAIT)
            event = await asyncio.wait_for(heard.events.get(), WAIT)
            assert sim._opcua is not None
            await sim._opcua.emit("Completed", {"achieved_torque": math.nan})  # a value no device may send
            anomaly = await asyncio.wait_for(heard.anomalies.get(), WAIT)
            await sim.stop()  # the server goes away under the session
            lost = await asyncio.wait_for(heard.lost.get(), WAIT)
        finally:
            await link.close()
    assert event == ("screwdriver-ua", "Completed", {"achieved_torque": 3.0})
    assert anomaly[0] == "screwdriver-ua" and anomaly[1].endswith("achieved_torque: nan is no finite number")
    assert lost[0] == "screwdriver-ua"
    assert lost[1].startswith(("the server closed the connection", "the OPC UA session ended")), lost
    assert heard.events.empty()


async def test_an_opc_ua_call_and_state_read_wait_as_long_as_they_are_told(monkeypatch: pytest.MonkeyPatch) -> None:
    release = asyncio.Event()

    async def never_answers(_device: SimulatedDevice, _request: str, _values: Mapping[str, Any]) -> None:
        await release.wait()

    monkeypatch.setattr(SimulatedDevice, "_on_opcua_call", never_answers)
    async with simulated(dataclasses.replace(device(MIXED, "binpicking-pc-ua"), command_timeout=LONG)) as (_, live):
        link = await Heard().open(dataclasses.replace(live, command_timeout=LONG))
        try:
            with pytest.raises(ProtocolTimeout, match=f"^device binpicking-pc-ua: no answer to call Localize within "
                                                      f"{SHORT:g} s$"):
                await asyncio.wait_for(link.request("Localize", {"PartType": "bracket"}, SHORT), WAIT)
            client = link._client  # type: ignore[attr-defined]
            monkeypatch.setattr(client, "_read_report", lambda _names: release.wait())  # a Read never answered
            with pytest.raises(ProtocolTimeout, match=f"^device binpicking-pc-ua: no answer to read its State within "
                                                      f"{SHORT:g} s$"):
                await asyncio.wait_for(link.state(SHORT), WAIT)
        finally:
            release.set()
            await link.close()


async def test_an_opc_ua_subscription_never_confirmed_is_given_up_after_the_command_timeout(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from plugnproduce.protocols.opcua import OpcUaDeviceClient

    release = asyncio.Event()
    monkeypatch.setattr(OpcUaDeviceClient, "_subscribe", lambda *_: release.wait())  # the server never confirms
    async with simulated(device(MIXED, "screwdriver-ua")) as (_, live):
        try:
            with pytest.raises(ProtocolTimeout, match=f"^device screwdriver-ua: no answer to subscribe to its events "
                                                      f"within {SHORT:g} s$"):
                await asyncio.wait_for(Heard().open(dataclasses.replace(live, command_timeout=SHORT)), WAIT)
        finally:
            release.set()


@pytest.mark.parametrize(("cell", "name", "state"), [(BIN_PICKING, "gripper", "open"),
                                                       (BIN_PICKING, "binpicking-pc", "ready")])
async def test_query_state_answers_the_state_of_its_device_chart(cell: Path, name: str, state: str) -> None:
    async with simulated(device(cell, name)) as (_, live):
        assert await query_state(live, WAIT) == state


async def test_query_report_reads_the_pose_the_robot_reports_with_its_state() -> None:
    async with simulated(device(BIN_PICKING, "robot")) as (_, live):
        state, values = await query_report(live, WAIT)
    assert (state, list(values)) == ("home", ["TargetPose"])
    assert list(values["TargetPose"]) == [0.4, 0.0, 0.6, 0.0, 180.0, 0.0]


@pytest.mark.parametrize("name", ["short-arm", "short-arm-upnp", "short-arm-ua"])
async def test_query_report_reads_the_reported_pose_over_each_protocol(name: str) -> None:
    async with simulated(device(SHORT_ARMS, name)) as (_, live):
        state, values = await query_report(live, WAIT)
    assert (state, list(values)) == ("home", ["TargetPose"])
    assert list(values["TargetPose"]) == [0.40, 0.00, 0.60, 0, 180, 0]


@pytest.mark.parametrize("name", ["short-arm", "short-arm-upnp", "short-arm-ua"])
async def test_query_report_waits_for_the_answer_as_long_as_it_is_told(monkeypatch: pytest.MonkeyPatch,
                                                                     name: str) -> None:
    release = asyncio.Event()

    async def never_answers(*_: Any) -> None:
        await release.wait()

    if name == "short-arm-ua":
        from plugnproduce.protocols.opcua import OpcUaDeviceClient
        monkeypatch.setattr(OpcUaDeviceClient, "_read_report", lambda *_: release.wait())  # a Read never answered
    elif name == "short-arm-upnp":
        monkeypatch.setattr(SimulatedDevice, "_on_upnp_action", never_answers)  # GetDeviceState never answered
    faults = never_answering()  # over XIRP: the state query's response is dropped
    async with simulated(dataclasses.replace(device(SHORT_ARMS, name), command_timeout=LONG),
                         faults=faults) as (_, live):
        try:
            with pytest.raises(ProtocolTimeout):
                await asyncio.wait_for(query_report(dataclasses.replace(live, command_timeout=LONG), SHORT), WAIT)
        finally:
            release.set()


async def test_a_protocol_no_link_speaks_is_refused_naming_the_three_that_are() -> None:
    odd = dataclasses.replace(device(BIN_PICKING, "gripper"), protocol="modbus")
    for opening in (Heard().open(odd), query_report(odd, WAIT)):
        with pytest.raises(ProtocolError, match="^device gripper: protocol 'modbus' is not supported; "
                                                "expected xirp, upnp or opcua$"):
            await opening


async def test_an_xirp_request_carries_its_values_to_the_device() -> None:
    async with simulated(device(BIN_PICKING, "robot")) as (sim, live):
        link = await Heard().open(live)
        try:
            await link.request("MoveTo", {"TargetPose": GUIDED, "Speed": 10}, WAIT)
            while await link.state(WAIT) != "at_pose":  # bounded: the robot's chart reaches it or the test fails
                await asyncio.sleep(0.02)
        finally:
            await link.close()
        state, values = await query_report(live, WAIT)
    assert state == "at_pose" and list(values["TargetPose"]) == GUIDED


def never_answering() -> xirp.Faults:
    """Faults of a device that takes Close and the state query but never answers either."""
    faults = xirp.Faults()
    for name in ("Close", "state"):
        faults.add(xirp.FaultKind.DROP_RESPONSE, name, times=None)
    return faults


async def test_an_xirp_link_waits_for_an_answer_as_long_as_it_is_told_not_as_the_device_says() -> None:
    gripper = dataclasses.replace(device(BIN_PICKING, "gripper"), command_timeout=LONG)
    async with simulated(gripper, faults=never_answering()) as (_, live):
        live = dataclasses.replace(live, command_timeout=LONG)
        link = await Heard().open(live)
        try:
            with pytest.raises(ProtocolTimeout, match=f"request Close to .*: no response within {SHORT:g} s$"):
                await asyncio.wait_for(link.request("Close", {"GripForce": 40}, SHORT), WAIT)
            with pytest.raises(ProtocolTimeout, match=f"request state to .*: no response within {SHORT:g} s$"):
                await asyncio.wait_for(link.state(SHORT), WAIT)
        finally:
            await link.close()
        with pytest.raises(ProtocolTimeout, match=f"no response within {SHORT:g} s$"):
            await asyncio.wait_for(query_state(live, SHORT), WAIT)


@asynccontextmanager
async def silent_server() -> AsyncIterator[int]:
    """A port on loopback that takes connections and never says a word."""
    held: list[tuple[asyncio.Task[Any] | None, asyncio.StreamWriter]] = []

    async def hold(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        held.append((asyncio.current_task(), writer))
        await reader.read()

    server = await asyncio.start_server(hold, "127.0.0.1", 0)
    try:
        yield server.sockets[0].getsockname()[1]
    finally:
        server.close()
        for _, writer in held:
            writer.close()
        await asyncio.gather(*(t for t, _ in held if t is not None), return_exceptions=True)
        await server.wait_closed()


@pytest.mark.parametrize(("floor", "command_timeout", "given_up"), [(SHORT, 2 * SHORT, 2 * SHORT),
                                                                     (2 * SHORT, SHORT, 2 * SHORT)])
async def test_a_device_that_never_greets_is_given_up_after_its_command_timeout_or_the_floor_if_longer(
        monkeypatch: pytest.MonkeyPatch, floor: float, command_timeout: float, given_up: float) -> None:
    monkeypatch.setattr(links, "CONNECT_TIMEOUT", floor)  # 10 s in earnest: a test need not wait that long
    async with silent_server() as port:
        silent = dataclasses.replace(device(BIN_PICKING, "gripper"), endpoint=f"xirp://127.0.0.1:{port}",
                                     command_timeout=command_timeout)
        with pytest.raises(ProtocolTimeout, match=f"no connection and hello within {given_up:g} s$"):
            await asyncio.wait_for(Heard().open(silent), WAIT)
        with pytest.raises(ProtocolTimeout, match=f"no connection and hello within {given_up:g} s$"):
            await asyncio.wait_for(query_report(silent, SHORT), WAIT)


@pytest.mark.parametrize(("floor", "command_timeout", "given_up"), [(SHORT, 2 * SHORT, 2 * SHORT),
                                                                     (2 * SHORT, SHORT, 2 * SHORT)])
async def test_an_opc_ua_server_that_never_answers_the_hello_is_given_up_after_the_command_timeout_or_the_floor(
        monkeypatch: pytest.MonkeyPatch, floor: float, command_timeout: float, given_up: float) -> None:
    monkeypatch.setattr(links, "CONNECT_TIMEOUT", floor)  # 10 s in earnest: a test need not wait that long
    async with silent_server() as port:
        silent = dataclasses.replace(device(MIXED, "screwdriver-ua"), endpoint=f"opc.tcp://127.0.0.1:{port}/pnp/x",
                                     command_timeout=command_timeout)
        said = f"^device screwdriver-ua: {silent.endpoint} did not open a session within {given_up:g} s$"
        with pytest.raises(ProtocolTimeout, match=said):
            await asyncio.wait_for(Heard().open(silent), WAIT)
        with pytest.raises(ProtocolTimeout, match=said):
            await asyncio.wait_for(query_report(silent, WAIT), WAIT)


async def test_a_upnp_link_waits_for_an_answer_as_long_as_it_is_told_not_as_the_device_says() -> None:
    release = asyncio.Event()

    async def handler(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        await release.wait()
        return {"Result": "accepted"}

    spec = upnp.with_state_query(upnp.service_spec_from_chart_events({"Localize": ["PartType"]}, []))
    async with upnp.UpnpDeviceServer("slow", "Slow PC", upnp.device_type_for("Localizer"), spec, handler,
                                     network=upnp.private_network()) as server:
        slow = dataclasses.replace(device(BIN_PICKING, "binpicking-pc"), id="slow", endpoint=server.location or "",
                                   command_timeout=LONG)
        link = await Heard().open(slow)
        try:
            with pytest.raises(ProtocolTimeout, match="Localize .*: no answer in time$"):
                await asyncio.wait_for(link.request("Localize", {"PartType": "bracket"}, SHORT), WAIT)
            with pytest.raises(ProtocolTimeout, match=f"{upnp.STATE_ACTION} .*: no answer in time$"):
                await asyncio.wait_for(link.state(SHORT), WAIT)
        finally:
            release.set()
            await link.close()


@pytest.mark.parametrize(("floor", "command_timeout", "given_up"), [(SHORT, 2 * SHORT, 2 * SHORT),
                                                                     (2 * SHORT, SHORT, 2 * SHORT)])
async def test_a_upnp_device_whose_description_never_comes_is_given_up_after_its_command_timeout_or_the_floor(
        monkeypatch: pytest.MonkeyPatch, floor: float, command_timeout: float, given_up: float) -> None:
    monkeypatch.setattr(links, "CONNECT_TIMEOUT", floor)  # 10 s in earnest: a test need not wait that long
    async with silent_server() as port:
        silent = dataclasses.replace(device(BIN_PICKING, "binpicking-pc"), command_timeout=command_timeout,
                                     endpoint=f"http://127.0.0.1:{port}/device.xml")
        said = f"^reading the description of device at {silent.endpoint}: no answer within {given_up:g} s$"
        with pytest.raises(ProtocolTimeout, match=said):
            await asyncio.wait_for(Heard().open(silent), WAIT)
        with pytest.raises(ProtocolTimeout, match=said):
            await asyncio.wait_for(query_report(silent, WAIT), WAIT)


@pytest.mark.parametrize("endpoint", ["http:/device.xml", "http:///device.xml", "binpicking-pc.local"])
async def test_a_upnp_endpoint_that_names_no_host_is_refused_naming_the_device_and_the_endpoint(endpoint: str) -> None:
    hostless = dataclasses.replace(device(BIN_PICKING, "binpicking-pc"), endpoint=endpoint)
    said = f"^device binpicking-pc: endpoint '{endpoint}' names no host; expected http://HOST:PORT/PATH$"
    for opening in (lambda: Heard().open(hostless), lambda: query_report(hostless, WAIT),
                    lambda: query_state(hostless, WAIT)):
        with pytest.raises(ProtocolError, match=said):
            await opening()


async def test_query_report_over_upnp_refuses_an_answer_without_a_state_or_with_a_value_that_is_no_json() -> None:
    answers = [{upnp.STATE_ARGUMENT: "", "TargetPose": "[]"}, {upnp.STATE_ARGUMENT: "home", "TargetPose": "a pose"}]

    async def handler(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        return answers.pop(0)

    spec = upnp.with_state_query(upnp.service_spec_from_chart_events({}, []), ["TargetPose"])
    async with upnp.UpnpDeviceServer("short-arm-upnp", "Recording arm", upnp.device_type_for("Robot"), spec, handler,
                                     network=upnp.private_network()) as server:
        arm = dataclasses.replace(device(SHORT_ARMS, "short-arm-upnp"), endpoint=server.location or "",
                                  command_timeout=WAIT)
        with pytest.raises(ProtocolError, match=f"^device short-arm-upnp: {upnp.STATE_ACTION} answered no "
                                                f"{upnp.STATE_ARGUMENT}$"):
            await query_report(arm, WAIT)
        with pytest.raises(ProtocolError, match=f"^device short-arm-upnp: {upnp.STATE_ACTION}: TargetPose"):
            await query_report(arm, WAIT)
