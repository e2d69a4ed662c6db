"""The live cell follows devices that announce themselves over SSDP on loopback."""

from __future__ import annotations

import asyncio
import socket
from collections.abc import Mapping
from typing import Any

import pytest

from plugnproduce.discovery import LiveCell
from plugnproduce.protocols.upnp import (
    DeviceFiles,
    SsdpNetwork,
    UpnpDeviceServer,
    device_type_for,
    service_spec_from_chart_events,
)
from plugnproduce.resources import descriptions_path

WAIT = 5.0


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


async def answer(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
    return {"Result": "accepted"}


def sensor_server(network: SsdpNetwork, device_id: str = "sensor3d") -> UpnpDeviceServer:
    folder = descriptions_path() / "devices"
    files = DeviceFiles("sensor3d.ttl", (folder / "sensor3d.ttl").read_text(), "sensor3d.scxml",
                        (folder / "sensor3d.scxml").read_text())
    spec = service_spec_from_chart_events({"Capture": ["Exposure"]}, ["CaptureDone"])
    return UpnpDeviceServer(device_id, "3D sensor", device_type_for("StereoCamera"), spec, answer, files=files,
                            network=network)


@pytest.fixture
def network() -> SsdpNetwork:
    return SsdpNetwork(port=free_udp_port())


async def test_device_present_at_start_is_in_the_cell(network, taxonomy) -> None:
    async with sensor_server(network), LiveCell(taxonomy, network=network) as live:
        change = await live.next_change(WAIT)
        assert (change.kind, change.device) == ("plug", "sensor3d")
        device = live.cell.device("sensor3d")
        assert "http://plugnproduce.org/ontology#CanSense3D" in device.skills
        assert {s.id for s in device.states} == {"ready", "capturing", "captured"}


async def test_plug_and_unplug_are_followed(network, taxonomy) -> None:
    async with LiveCell(taxonomy, network=network) as live:
        assert live.cell.devices == ()
        server = sensor_server(network)
        await server.start()
        plugged = await live.next_change(WAIT)
        assert (plugged.kind, plugged.device) == ("plug", "sensor3d")
        await server.stop()
        unplugged = await live.next_change(WAIT)
        assert (unplugged.kind, unplugged.device) == ("unplug", "sensor3d")
        assert unplugged.cell.devices == ()


async def test_entering_returns_once_the_expected_devices_have_answered(network, taxonomy) -> None:
    # A search window far longer than the bound: entering must not wait for the window to end.
    async with sensor_server(network), asyncio.timeout(WAIT):
        async with LiveCell(taxonomy, network=network, search_timeout=3600, expected=["sensor3d"]) as live:
            assert [d.id for d in live.cell.devices] == ["sensor3d"]


async def test_an_expected_device_that_never_answers_costs_the_window_only(network, taxonomy) -> None:
    async with sensor_server(network), asyncio.timeout(WAIT):
        async with LiveCell(taxonomy, network=network, search_timeout=1, expected=["gripper", "sensor3d"]) as live:
            assert [d.id for d in live.cell.devices] == ["sensor3d"]
