"""OPC UA on loopback: simulated devices as asyncua servers, seen by asyncua's own client and by ours."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, Server, ua

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.description.model import DeviceDescription
from plugnproduce.errors import ProtocolConnectionError, ProtocolError, ProtocolTimeout, RemoteError
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua import MAX_ARRAY, OpcUaDeviceClient, namespace_for
from plugnproduce.protocols.opcua.space import new_server
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT


def _device(name: str) -> DeviceDescription:
    return load_device(Path(service.builtin("devices", f"{name}.ttl")), load_taxonomy())


@pytest.fixture
async def screwdriver() -> AsyncIterator[SimulatedDevice]:
    async with SimulatedDevice(_device("screwdriver-ua")) as device:
        yield device


async def _until(condition: Any, what: str) -> None:
    deadline = asyncio.get_running_loop().time() + WAIT
    while not condition():
        assert asyncio.get_running_loop().time() < deadline, what
        await asyncio.sleep(0.01)


class _Collect:
    def __init__(self) -> None:
        self.events: list[Any] = []

    def event_notification(self, event: Any) -> None:
        self.events.append(event)


async def test_asyncuas_own_client_browses_the_device_and_runs_its_skill(screwdriver: SimulatedDevice) -> None:
    """A plain asyncua client (none of our code) finds the device by browsing, reads its state, subscribes to
    its events and calls Start with a Double: the PackML skill runs to Complete and reports the torque."""
    assert screwdriver.endpoint.startswith("opc.tcp://127.0.0.1:")
    async with Client(screwdriver.endpoint, timeout=WAIT) as client:
        ns = await client.get_namespace_index(namespace_for("screwdriver-ua"))
        names = {(await n.read_browse_name()).Name: n for n in await client.nodes.objects.get_children()}
        device = names["screwdriver-ua"]
        children = {(await n.read_browse_name()).Name: n for n in await device.get_children()}
        assert {"Start", "Stop", "Abort", "Reset", "State"} <= set(children)
        assert await children["State"].read_value() == "Idle"
        inputs = await (await children["Start"].get_child("0:InputArguments")).read_value()
        assert [(a.Name, a.DataType.Identifier) for a in inputs] == [("Torque", ua.ObjectIds.Double)]
        collect = _Collect()
        subscription = await client.create_subscription(20, collect)
        completed = await client.get_node(ua.ObjectIds.BaseEventType).get_child(f"{ns}:Completed")
        await subscription.subscribe_events(device, completed)
        assert await device.call_method(f"{ns}:Start", ua.Variant(3.5, ua.VariantType.Double)) is None
        await _until(lambda: collect.events, "no Completed event")
        assert collect.events[0].achieved_torque == 3.5
        assert await children["State"].read_value() == "Complete"


async def test_a_request_the_state_does_not_take_is_refused_and_moves_nothing(screwdriver: SimulatedDevice) -> None:
    client = await OpcUaDeviceClient.connect(screwdriver.endpoint, "screwdriver-ua", WAIT)
    try:
        with pytest.raises(RemoteError, match="does not accept it in its current state: call Reset: BadInvalidState"):
            await client.call("Reset", {}, WAIT)
        assert await client.state(WAIT) == screwdriver.state == "Idle"
        with pytest.raises(ProtocolError, match="Start argument Torque: expected a number"):
            await client.call("Start", {"Torque": "fast"}, WAIT)
        with pytest.raises(ProtocolError, match="method Start needs argument Torque"):
            await client.call("Start", {}, WAIT)
        assert screwdriver.state == "Idle"
    finally:
        await client.close()


async def test_the_safe_stop_is_the_skills_stop() -> None:
    device = _device("screwdriver-ua")
    assert device.stop_from("Execute") is not None and device.stop_from("Execute").request.name == "Stop"
    assert device.stop_from("Stopping") is not None and device.stop_from("Stopping").request.name == "Abort"
    async with SimulatedDevice(device) as sim:
        client = await OpcUaDeviceClient.connect(sim.endpoint, device.id, WAIT)
        try:
            await client.call("Start", {"Torque": 2.0}, WAIT)
            await _until(lambda: sim.state == "Execute", "the skill did not execute")
            await client.call("Stop", {}, WAIT)
            await _until(lambda: sim.state == "Stopped", "the skill did not stop")
            assert await client.state(WAIT) == "Stopped"
        finally:
            await client.close()


async def test_output_arguments_carry_the_answer_with_opc_ua_types() -> None:
    async with SimulatedDevice(_device("binpicking-pc-ua")) as sim:
        async with Client(sim.endpoint, timeout=WAIT) as plain:  # the types on the wire, as any client sees them
            ns = await plain.get_namespace_index(namespace_for("binpicking-pc-ua"))
            node = await plain.nodes.objects.get_child(f"{ns}:binpicking-pc-ua")
            result = await node.call_method(f"{ns}:Localize", ua.Variant("bracket", ua.VariantType.String))
        assert result == ["PartFound", [0.4, 0.1, 0.05, 0.0, 180.0, 0.0], "bracket"]
        client = await OpcUaDeviceClient.connect(sim.endpoint, "binpicking-pc-ua", WAIT)
        try:
            outputs = await client.call("Localize", {"PartType": "bracket"}, WAIT)
        finally:
            await client.close()
    assert outputs == {"outcome": "PartFound", "part_pose": [0.4, 0.1, 0.05, 0.0, 180.0, 0.0], "part_type": "bracket"}


# --- servers that misbehave ---------------------------------------------------------------------------------

@pytest.fixture
async def hostile() -> AsyncIterator[tuple[Server, str]]:
    """A server with the device's namespace and object whose methods misbehave."""
    server = await new_server()  # the standard address space as every server of the package gets it
    server.set_endpoint("opc.tcp://127.0.0.1:0/hostile")
    server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
    idx = await server.register_namespace(namespace_for("hostile"))
    device = await server.nodes.objects.add_object(idx, "hostile")
    out = [ua.Argument(Name="values", DataType=ua.NodeId(ua.ObjectIds.Double), ValueRank=1)]

    async def huge(_parent: ua.NodeId) -> list[ua.Variant]:
        return [ua.Variant([1.0] * (MAX_ARRAY + 1), ua.VariantType.Double)]

    async def slow(_parent: ua.NodeId) -> list[ua.Variant]:
        await asyncio.sleep(3600)
        return []

    await device.add_method(idx, "Huge", huge, [], out)
    await device.add_method(idx, "Slow", slow, [], [])
    await device.add_variable(idx, "State", [1, 2, 3])
    await server.start()
    port = server.bserver._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
    try:
        yield server, f"opc.tcp://127.0.0.1:{port}/hostile"
    finally:
        await server.stop()


async def test_a_huge_array_a_slow_method_and_a_bad_state_are_clear_errors(hostile: tuple[Server, str]) -> None:
    client = await OpcUaDeviceClient.connect(hostile[1], "hostile", WAIT)
    try:
        with pytest.raises(ProtocolError, match=f"Huge output values: an array of {MAX_ARRAY + 1} values; at most"):
            await client.call("Huge", {}, WAIT)
        with pytest.raises(ProtocolError, match="State is .*expected the id of a chart state"):
            await client.state(WAIT)
        with pytest.raises(RemoteError, match="call Missing"):
            await client.call("Missing", {}, WAIT)
        with pytest.raises(ProtocolTimeout, match="device hostile: no answer to call Slow within 0.5 s"):
            await client.call("Slow", {}, 0.5)  # last: the server answers nothing else on this session meanwhile
    finally:
        await client.close()


async def test_a_server_without_the_devices_namespace_is_refused(hostile: tuple[Server, str]) -> None:
    with pytest.raises(ProtocolError, match="device gripper: the server has no namespace "
                                            "http://plugnproduce.org/opcua/gripper"):
        await OpcUaDeviceClient.connect(hostile[1], "gripper", WAIT)


async def test_nothing_listening_is_a_connection_error() -> None:
    probe = await asyncio.start_server(lambda *_: None, "127.0.0.1", 0)
    port = probe.sockets[0].getsockname()[1]
    probe.close()
    await probe.wait_closed()
    with pytest.raises(ProtocolConnectionError, match=f"device d: cannot connect to opc.tcp://127.0.0.1:{port}/x"):
        await OpcUaDeviceClient.connect(f"opc.tcp://127.0.0.1:{port}/x", "d", WAIT)


async def test_a_silent_server_is_a_timeout() -> None:
    """A TCP server that accepts and never says a word (no OPC UA Acknowledge) blinds nothing."""
    writers: list[asyncio.StreamWriter] = []

    async def silent(_reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        writers.append(writer)

    server = await asyncio.start_server(silent, "127.0.0.1", 0)
    port = server.sockets[0].getsockname()[1]
    try:
        with pytest.raises(ProtocolError, match="device d: "):
            await OpcUaDeviceClient.connect(f"opc.tcp://127.0.0.1:{port}/x", "d", 0.5)
    finally:
        for writer in writers:
            writer.close()
        server.close()
        await server.wait_closed()


@pytest.mark.parametrize("endpoint", ["xirp://127.0.0.1:4840", "opc.tcp://host", "opc.tcp://h:99999/x",
                                      "opc.tcp://a b:1/"])
async def test_an_endpoint_that_is_no_opc_tcp_url_is_refused_before_any_connection(endpoint: str) -> None:
    with pytest.raises(ProtocolError, match="OPC UA endpoint"):
        await OpcUaDeviceClient.connect(endpoint, "d", WAIT)
