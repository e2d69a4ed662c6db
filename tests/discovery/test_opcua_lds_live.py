"""Discovery through a Local Discovery Server, followed live: registrations are renewed, end when the device
stops (or stops renewing), and the live cell plugs and unplugs the OPC UA devices as the LDS lists them, with no
SSDP between it and the devices."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.description.model import DeviceDescription
from plugnproduce.discovery import LiveCell
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua import NodeSpec, OpcUaDeviceServer
from plugnproduce.protocols.opcua.discovery import KEEP, LocalDiscoveryServer, find_servers
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT


@pytest.fixture
async def lds(request: pytest.FixtureRequest) -> AsyncIterator[LocalDiscoveryServer]:
    """An LDS on a free loopback port keeping a registration 2 s (the simulated devices renew theirs every 30 s:
    the live cell's test keeps them the standard time)."""
    server = LocalDiscoveryServer(port=0, keep=2.0 if "live_cell" not in request.node.name else KEEP)
    await server.start()
    try:
        yield server
    finally:
        await server.stop()


def _device(name: str) -> DeviceDescription:
    return load_device(Path(service.builtin("devices", f"{name}.ttl")), load_taxonomy())


async def _listed(lds: LocalDiscoveryServer) -> list[str]:
    assert lds.endpoint is not None
    return [device for device, _ in await find_servers(lds.endpoint, WAIT)]


async def _until(condition: object, what: str) -> None:
    deadline = asyncio.get_running_loop().time() + WAIT
    while not await condition():  # type: ignore[operator]
        assert asyncio.get_running_loop().time() < deadline, what
        await asyncio.sleep(0.05)


async def _refuse(*_: object) -> None:
    return None


async def test_a_renewed_registration_stays_and_a_stopping_device_leaves_at_once(lds: LocalDiscoveryServer) -> None:
    """Renewed every second, the registration outlives the LDS's 2 s keep; the device stopping says it goes
    offline, and the LDS lists it no more."""
    assert lds.endpoint is not None
    device = OpcUaDeviceServer(NodeSpec("nutrunner"), _refuse, lambda: "Idle")
    await device.start()
    try:
        await device.register(lds.endpoint, period=1)
        first = lds.registrations
        await _until(lambda: _renewals_past(lds, first + 3), "the registration was not renewed")
        assert await _listed(lds) == ["nutrunner"]
    finally:
        await device.stop()
    assert await _listed(lds) == []


async def _renewals_past(lds: LocalDiscoveryServer, count: int) -> bool:
    return lds.registrations >= count


async def test_a_registration_not_renewed_expires(lds: LocalDiscoveryServer) -> None:
    """A device that registered once and never again (it died) leaves the list once the keep has passed."""
    assert lds.endpoint is not None
    device = OpcUaDeviceServer(NodeSpec("ghost"), _refuse, lambda: "Idle")
    await device.start()
    try:
        await device.register(lds.endpoint, period=0)
        assert await _listed(lds) == ["ghost"]

        async def gone() -> bool:
            return await _listed(lds) == []

        await _until(gone, "the stale registration was still listed")
    finally:
        await device.stop()


async def test_the_live_cell_plugs_and_unplugs_what_the_lds_lists(lds: LocalDiscoveryServer) -> None:
    """The devices announce themselves by SSDP on one private port, the controller searches another: only the
    LDS tells it of them. A device that stops is unplugged; started again, it is plugged again."""
    assert lds.endpoint is not None
    devices, controller = private_network(), private_network()
    nutrunner = SimulatedDevice(_device("screwdriver-ua"), network=devices, lds=lds.endpoint)
    async with SimulatedDevice(_device("binpicking-pc-ua"), network=devices, lds=lds.endpoint) as localizer:
        await nutrunner.start()
        try:
            async with LiveCell(load_taxonomy(), network=controller, lds=lds.endpoint, search_timeout=WAIT,
                                expected=["screwdriver-ua", "binpicking-pc-ua"]) as live:
                assert {d.id: d.endpoint for d in live.cell.devices} == {
                    "binpicking-pc-ua": localizer.endpoint, "screwdriver-ua": nutrunner.endpoint}
                started = [await live.next_change(WAIT) for _ in range(2)]  # the plugs of the start
                assert sorted((c.kind, c.device) for c in started) == [
                    ("plug", "binpicking-pc-ua"), ("plug", "screwdriver-ua")]
                await nutrunner.stop()
                change = await live.next_change(WAIT)
                assert (change.kind, change.device) == ("unplug", "screwdriver-ua")
                assert [d.id for d in live.cell.devices] == ["binpicking-pc-ua"]
                await nutrunner.start()
                change = await live.next_change(WAIT)
                assert (change.kind, change.device) == ("plug", "screwdriver-ua")
                assert {d.id: d.endpoint for d in live.cell.devices}["screwdriver-ua"] == nutrunner.endpoint
        finally:
            await nutrunner.stop()
