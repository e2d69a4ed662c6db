"""Discovery without configuration over OPC UA: devices register with a Local Discovery Server, the controller
asks it (FindServers) and reads each device's own description from the device, by the trust rules of UPnP."""

from __future__ import annotations

from collections.abc import AsyncIterator
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.discovery.opcua import discover_on_lds
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.opcua import NodeSpec, OpcUaDeviceServer
from plugnproduce.protocols.opcua.discovery import LocalDiscoveryServer
from plugnproduce.sim.device import SimulatedDevice, served_description
from tests.lines import WAIT


@pytest.fixture
async def lds() -> AsyncIterator[str]:
    server = LocalDiscoveryServer(port=0)
    await server.start()
    assert server.endpoint is not None
    try:
        yield server.endpoint
    finally:
        await server.stop()


def _device(name: str):  # type: ignore[no-untyped-def]
    return load_device(Path(service.builtin("devices", f"{name}.ttl")), load_taxonomy())


async def test_devices_registered_with_the_lds_are_found_with_their_real_endpoints(lds: str) -> None:
    async with SimulatedDevice(_device("screwdriver-ua"), lds=lds) as nutrunner, \
            SimulatedDevice(_device("binpicking-pc-ua"), lds=lds) as localizer:
        found, refused = await discover_on_lds(lds, load_taxonomy(), WAIT)
        endpoints = {"screwdriver-ua": nutrunner.endpoint, "binpicking-pc-ua": localizer.endpoint}
    assert refused == []
    assert {d.id: d.endpoint for d in found} == endpoints
    nutrunner_found = next(d for d in found if d.id == "screwdriver-ua")
    assert nutrunner_found.protocol == "opcua" and nutrunner_found.initial == "Idle"
    assert {t.request.name for t in nutrunner_found.stops if t.request} == {"Stop", "Abort"}


async def test_a_device_naming_an_endpoint_on_another_host_is_refused_and_the_honest_one_found(lds: str) -> None:
    """A server that registers as a device but whose Turtle names an endpoint elsewhere is refused, named;
    a registration whose server is gone is refused too; the honest device is found all the same."""
    liar = _device("screwdriver-ua")

    def elsewhere(_endpoint: str) -> DeviceFiles:
        turtle, chart = served_description(liar, "opc.tcp://192.0.2.7:4840/pnp/screwdriver-ua")
        return DeviceFiles("screwdriver-ua.ttl", turtle, "screwdriver-ua.scxml", chart)

    async def refuse(*_: object) -> None:
        return None

    hostile = OpcUaDeviceServer(NodeSpec("screwdriver-ua"), refuse, lambda: "Idle", files=elsewhere)
    gone = OpcUaDeviceServer(NodeSpec("ghost"), refuse, lambda: "Idle")
    await hostile.start()
    await gone.start()
    try:
        await hostile.register(lds)
        await gone.register(lds)
        await gone.stop()
        async with SimulatedDevice(_device("binpicking-pc-ua"), lds=lds) as honest:
            found, refused = await discover_on_lds(lds, load_taxonomy(), 5.0)
            assert [(d.id, d.endpoint) for d in found] == [("binpicking-pc-ua", honest.endpoint)]
    finally:
        await hostile.stop()
    reasons = {r.udn: r.reason for r in refused}
    assert set(reasons) == {"urn:plugnproduce:device:screwdriver-ua", "urn:plugnproduce:device:ghost"}
    assert "names OPC UA endpoint opc.tcp://192.0.2.7:4840/pnp/screwdriver-ua on another host; refused" \
        in reasons["urn:plugnproduce:device:screwdriver-ua"]
    assert "device ghost: cannot connect to opc.tcp://127.0.0.1:" in reasons["urn:plugnproduce:device:ghost"]
