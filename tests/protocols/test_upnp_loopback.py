"""The UPnP device and controller sides against each other, over real loopback sockets.

Each test gets a private SSDP port (a free one), so parallel runs never see each
other's devices; HTTP servers bind port 0. Nothing sleeps: every wait is for a
condition, with a timeout.
"""

from __future__ import annotations

import asyncio
import socket
import uuid
from collections.abc import AsyncIterator, Awaitable, Callable, Mapping
from typing import Any

import pytest

from plugnproduce.errors import ProtocolConnectionError, ProtocolError, ProtocolTimeout, RemoteError
from plugnproduce.protocols.upnp import (
    NOT_ACCEPTED_NOW,
    ActionFailed,
    ActionSpec,
    AdvertisementListener,
    ArgumentSpec,
    DeviceFiles,
    DeviceSearch,
    SearchHit,
    ServiceSpec,
    SsdpNetwork,
    UntrustedUrlError,
    UpnpDeviceClient,
    UpnpDeviceServer,
    VariableSpec,
    describe,
    device_type_for,
    discover,
    service_spec_from_chart_events,
)
from tests.lines import WAIT

CHART_SPEC = service_spec_from_chart_events({"MoveTo": ["Pose"], "Home": []}, ["arrived"])
SPEC = ServiceSpec(
    CHART_SPEC.actions
    + (
        ActionSpec("SetMode", (ArgumentSpec("Mode", allowed_values=("auto", "manual")),)),
        ActionSpec("SetSpeed", (ArgumentSpec("Speed", "i4"),)),
    ),
    CHART_SPEC.variables + (VariableSpec("Mode", allowed_values=("auto", "manual"), default="auto"),),
)
FILES = DeviceFiles("robot.ttl", "dev:robot pnp:stateChart <robot.scxml> .\n", "robot.scxml", '<scxml name="robot"/>\n')


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture
def network() -> SsdpNetwork:
    """A private SSDP port on loopback."""
    return SsdpNetwork(port=free_udp_port())


class Recorder:
    """An action handler that records its calls and answers ``Result``."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, dict[str, Any]]] = []

    async def __call__(self, action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        self.calls.append((action, dict(arguments)))
        return {"Result": f"done {action}"}


@pytest.fixture
def recorder() -> Recorder:
    return Recorder()


def new_device(network: SsdpNetwork, handler: Callable[..., Awaitable[Mapping[str, Any]]]) -> UpnpDeviceServer:
    device_id = f"robot-{uuid.uuid4().hex[:8]}"
    return UpnpDeviceServer(
        device_id, "Test robot", device_type_for("Robot"), SPEC, handler, files=FILES, network=network
    )


@pytest.fixture
async def device(network: SsdpNetwork, recorder: Recorder) -> AsyncIterator[UpnpDeviceServer]:
    async with new_device(network, recorder) as server:
        yield server


@pytest.fixture
async def client(device: UpnpDeviceServer) -> AsyncIterator[UpnpDeviceClient]:
    assert device.location is not None
    async with await UpnpDeviceClient.connect(device.location, "127.0.0.1", timeout=WAIT) as upnp_client:
        yield upnp_client


async def test_device_is_found_by_ssdp_search(network: SsdpNetwork, device: UpnpDeviceServer) -> None:
    async with DeviceSearch(network) as search:
        hit = await search.wait_for(device.udn, WAIT)
    assert hit == SearchHit(device.udn, str(device.location), "127.0.0.1")


async def test_discover_reads_type_and_name_of_each_device(network: SsdpNetwork, device: UpnpDeviceServer) -> None:
    found = await discover(WAIT, network=network, expected=[device.udn])  # ends once the device has answered
    assert [(d.udn, d.device_type, d.friendly_name) for d in found.devices] == [
        (device.udn, "urn:plugnproduce-org:device:Robot:1", "Test robot")
    ]
    assert found.refused == ()


async def test_discover_ends_once_the_expected_devices_have_answered(network: SsdpNetwork,
                                                                    device: UpnpDeviceServer) -> None:
    async with asyncio.timeout(WAIT):  # the suite's limit, far shorter than the search window
        found = await discover(3600, network=network, expected=[device.udn])
    assert [d.udn for d in found.devices] == [device.udn]


async def test_action_is_invoked_with_its_argument(client: UpnpDeviceClient, recorder: Recorder) -> None:
    result = await client.call("MoveTo", Pose="0.4 0.1 0.2 0 180 0")
    assert result == {"Result": "done MoveTo"}
    assert recorder.calls == [("MoveTo", {"Pose": "0.4 0.1 0.2 0 180 0"})]


async def test_typed_argument_arrives_typed(client: UpnpDeviceClient, recorder: Recorder) -> None:
    await client.call("SetSpeed", Speed="40")
    assert recorder.calls == [("SetSpeed", {"Speed": 40})]


async def test_client_lists_actions_and_variables(client: UpnpDeviceClient, device: UpnpDeviceServer) -> None:
    assert client.actions["MoveTo"] == ("Pose",)
    assert set(client.variables) == {"arrived", "Mode"}
    assert (client.udn, client.friendly_name) == (device.udn, "Test robot")


async def test_event_arrives_after_the_device_changes_a_variable(
    client: UpnpDeviceClient, device: UpnpDeviceServer
) -> None:
    await client.subscribe()
    assert client.values == {"arrived": 0, "Mode": "auto"}
    await device.set_variable("Mode", "manual")
    assert await client.next_change(WAIT) == ("Mode", "manual")


async def test_device_without_events_can_be_subscribed(network: SsdpNetwork, recorder: Recorder) -> None:
    spec = service_spec_from_chart_events({"Home": []}, [])
    async with UpnpDeviceServer("quiet", "Quiet", device_type_for("Robot"), spec, recorder, network=network) as server:
        async with await UpnpDeviceClient.connect(str(server.location), "127.0.0.1", timeout=WAIT) as upnp_client:
            await upnp_client.subscribe()
            assert upnp_client.values == {}


async def test_every_emitted_chart_event_is_a_change(client: UpnpDeviceClient, device: UpnpDeviceServer) -> None:
    seen: asyncio.Queue[tuple[str, Any]] = asyncio.Queue()
    await client.subscribe(lambda variable, value: seen.put_nowait((variable, value)))
    await device.emit("arrived")
    await device.emit("arrived")
    await client.wait_until(lambda values: values.get("arrived") == 2, WAIT)
    assert [await asyncio.wait_for(seen.get(), WAIT) for _ in range(2)] == [("arrived", 1), ("arrived", 2)]


async def test_alive_and_byebye_reach_the_listener(network: SsdpNetwork, recorder: Recorder) -> None:
    async with AdvertisementListener(network) as listener:
        server = new_device(network, recorder)
        async with server:
            alive = await listener.wait_for(server.udn, True, WAIT)
            assert (alive.location, alive.source_host) == (server.location, "127.0.0.1")
        await listener.wait_for(server.udn, False, WAIT)
    assert [a.alive for a in listener.seen if a.udn == server.udn] == [True, False]


async def test_description_on_another_host_is_refused(device: UpnpDeviceServer) -> None:
    moved = str(device.location).replace("127.0.0.1", "127.0.0.2")
    with pytest.raises(UntrustedUrlError) as info:
        await describe(SearchHit(device.udn, moved, "127.0.0.1"))
    assert "points at host 127.0.0.2" in str(info.value)
    assert "discovered at 127.0.0.1" in str(info.value)


async def test_client_refuses_a_location_off_its_trusted_host(device: UpnpDeviceServer) -> None:
    with pytest.raises(UntrustedUrlError):
        await UpnpDeviceClient.connect(str(device.location), "127.0.0.2")


async def test_argument_outside_allowed_values_is_refused_before_sending(
    client: UpnpDeviceClient, recorder: Recorder
) -> None:
    with pytest.raises(ProtocolError) as info:
        await client.call("SetMode", Mode="turbo")
    assert "argument 'Mode' = 'turbo' is refused; expected one of auto, manual" in str(info.value)
    assert recorder.calls == []


async def test_variable_value_outside_allowed_values_is_refused(device: UpnpDeviceServer) -> None:
    with pytest.raises(ProtocolError) as info:
        await device.set_variable("Mode", "turbo")
    assert "value 'turbo' for state variable 'Mode' is refused; expected one of auto, manual" in str(info.value)
    assert device.value("Mode") == "auto"


async def test_wrong_arguments_and_unknown_actions_are_refused(client: UpnpDeviceClient) -> None:
    with pytest.raises(ProtocolError, match=r"missing: \['Pose'\], unknown: \['pose'\]"):
        await client.call("MoveTo", pose="0 0 0 0 0 0")
    with pytest.raises(ProtocolError, match="has no action 'Fly'; it has: Home, MoveTo, SetMode, SetSpeed"):
        await client.call("Fly")


async def test_refusal_by_the_device_is_a_remote_error(network: SsdpNetwork) -> None:
    async def refuse(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        raise ActionFailed("not waiting for Home now", code=NOT_ACCEPTED_NOW)

    async with new_device(network, refuse) as server:
        async with await UpnpDeviceClient.connect(str(server.location), "127.0.0.1") as upnp_client:
            with pytest.raises(RemoteError, match=r"UPnP error 701 \(not waiting for Home now\)"):
                await upnp_client.call("Home")


async def test_failing_handler_is_a_remote_error(network: SsdpNetwork) -> None:
    async def broken(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        raise RuntimeError("chart not loaded")

    async with new_device(network, broken) as server:
        async with await UpnpDeviceClient.connect(str(server.location), "127.0.0.1") as upnp_client:
            with pytest.raises(RemoteError, match="UPnP error 501") as info:
                await upnp_client.call("Home")
    assert "chart not loaded" not in str(info.value)  # a handler's bug stays on the device's side


async def test_wrongly_typed_argument_is_refused(client: UpnpDeviceClient) -> None:
    with pytest.raises(ProtocolError, match="argument 'Speed' = 'fast' is refused; expected a i4"):
        await client.call("SetSpeed", Speed="fast")


async def test_subscribing_twice_is_refused(client: UpnpDeviceClient) -> None:
    await client.subscribe()
    with pytest.raises(ProtocolError, match="already subscribed"):
        await client.subscribe()


async def test_closing_after_the_device_left_is_quiet(client: UpnpDeviceClient, device: UpnpDeviceServer) -> None:
    await client.subscribe()
    await device.stop()
    await client.close()
    assert client.values == {"arrived": 0, "Mode": "auto"}


async def test_slow_device_gives_a_timeout(network: SsdpNetwork) -> None:
    release = asyncio.Event()

    async def slow(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        await release.wait()
        return {"Result": "late"}

    async with new_device(network, slow) as server:
        async with await UpnpDeviceClient.connect(str(server.location), "127.0.0.1") as upnp_client:
            with pytest.raises(ProtocolTimeout, match="Home on device 'Test robot'"):
                await upnp_client.invoke("Home", {}, timeout=0.2)
        release.set()


async def test_device_files_are_fetched_from_the_device(client: UpnpDeviceClient, device: UpnpDeviceServer) -> None:
    files = await client.fetch_files()
    base = str(device.location).removesuffix("/device.xml")
    assert (files.description_url, files.chart_url) == (f"{base}/pnp/robot.ttl", f"{base}/pnp/robot.scxml")
    assert (files.description, files.chart) == (FILES.description, FILES.chart)


async def test_unreachable_device_is_a_connection_error() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    with pytest.raises(ProtocolConnectionError, match="cannot connect"):
        await UpnpDeviceClient.connect(f"http://127.0.0.1:{port}/device.xml", "127.0.0.1", timeout=WAIT)
