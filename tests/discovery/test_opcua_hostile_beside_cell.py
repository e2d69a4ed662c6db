"""Hostile OPC UA servers beside the cell change nothing for the honest devices: discovery through the Local
Discovery Server finds the honest ones and names each hostile one it refuses, and a task then runs on the
honest devices while the hostile servers are still there (one of them holding a session that never answers)."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator, Awaitable, Callable
from contextlib import AsyncExitStack
from pathlib import Path
from typing import Any

import pytest
from asyncua import Node, Server, ua

from plugnproduce import controller, service
from plugnproduce.description.loader import load_device
from plugnproduce.discovery.opcua import discover_on_lds
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua.discovery import LocalDiscoveryServer
from plugnproduce.protocols.opcua.space import new_server
from plugnproduce.protocols.opcua.spec import MAX_ARRAY, application_uri_for, format_endpoint, namespace_for
from plugnproduce.sim.device import SimulatedDevice

TIMEOUT = 15.0
"""Each device's budget: generous for an honest device on a loaded machine, and what the silent one costs."""
Build = Callable[[Server, Node, int], Awaitable[None]]


async def _texts(device: Node, idx: int, values: dict[str, ua.Variant]) -> None:
    folder = await device.add_object(idx, "Description")
    for name, value in values.items():
        await folder.add_variable(idx, name, value)


async def _huge_array(_server: Server, device: Node, idx: int) -> None:
    await _texts(device, idx, {"TurtleName": ua.Variant("d.ttl"),
                               "Turtle": ua.Variant(["@prefix x: <y#> ."] * (4 * MAX_ARRAY), ua.VariantType.String),
                               "ChartName": ua.Variant("d.scxml"), "Chart": ua.Variant("<scxml/>")})


async def _far_too_large(_server: Server, device: Node, idx: int) -> None:
    await _texts(device, idx, {"TurtleName": ua.Variant("d.ttl"), "Turtle": ua.Variant("#" * (3 << 20)),
                               "ChartName": ua.Variant("d.scxml"), "Chart": ua.Variant("<scxml/>")})


async def _bad_types(_server: Server, device: Node, idx: int) -> None:
    await _texts(device, idx, {"TurtleName": ua.Variant(ua.LocalizedText("d.ttl")),
                               "Turtle": ua.Variant(42, ua.VariantType.Int64),
                               "ChartName": ua.Variant(b"\x00\xff", ua.VariantType.ByteString),
                               "Chart": ua.Variant(ua.QualifiedName("x", 0))})


async def _endless_browse(_server: Server, device: Node, idx: int) -> None:
    """No description where the naming rule says, but a deep chain and a wide fan of objects to get lost in."""
    node = device
    for level in range(200):
        node = await node.add_object(idx, f"Level{level}")
    for n in range(500):
        await device.add_object(idx, f"Wide{n}")


HOSTILE: dict[str, Build] = {"huge-array": _huge_array, "far-too-large": _far_too_large,
                             "bad-types": _bad_types, "endless-browse": _endless_browse}


async def _hostile(name: str, build: Build, lds: str) -> Server:
    server = await new_server()  # the standard address space as every server of the package gets it
    server.set_endpoint(format_endpoint("127.0.0.1", 0, f"/pnp/{name}"))
    server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
    await server.set_application_uri(application_uri_for(name))
    idx = await server.register_namespace(namespace_for(name))
    await build(server, await server.nodes.objects.add_object(idx, name), idx)
    await server.start()
    port = server.bserver._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
    server.set_endpoint(format_endpoint("127.0.0.1", port, f"/pnp/{name}"))
    await server.register_to_discovery(lds, period=0)
    return server


async def _silent(lds: str, writers: list[asyncio.StreamWriter]) -> asyncio.Server:
    """A server that registers, then falls silent: its port accepts connections and never says a word."""
    server = await _hostile("silent", _huge_array, lds)
    port = server.bserver._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
    await server.stop()

    async def mute(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        writers.append(writer)
        while await reader.read(4096):
            pass

    return await asyncio.start_server(mute, "127.0.0.1", port)


def _hang_up(server: asyncio.Server, writers: list[asyncio.StreamWriter]) -> None:
    for writer in writers:
        writer.close()
    server.close()


@pytest.fixture
async def lds() -> AsyncIterator[str]:
    server = LocalDiscoveryServer(port=0)
    await server.start()
    assert server.endpoint is not None
    try:
        yield server.endpoint
    finally:
        await server.stop()


async def test_hostile_servers_beside_the_cell_change_nothing_for_the_honest_devices(lds: str,
                                                                                     tmp_path: Path) -> None:
    taxonomy = load_taxonomy()
    async with AsyncExitStack() as stack:
        for name, build in HOSTILE.items():
            stack.push_async_callback((await _hostile(name, build, lds)).stop)
        writers: list[asyncio.StreamWriter] = []
        stack.callback(_hang_up, await _silent(lds, writers), writers)
        honest = {}
        for name in ("screwdriver-ua", "binpicking-pc-ua"):
            device = load_device(Path(service.builtin("devices", f"{name}.ttl")), taxonomy)
            honest[name] = (await stack.enter_async_context(SimulatedDevice(device, lds=lds))).endpoint
        found, refused = await discover_on_lds(lds, taxonomy, TIMEOUT)
        report = await controller.run_task(service.builtin("tasks", "pick-and-screw.yaml"),
                                           service.builtin("cells", "mixed.yaml"), simulate=True,
                                           journal=tmp_path / "run.jsonl")
    assert {d.id: d.endpoint for d in found} == honest
    reasons: dict[str, Any] = {r.udn.removeprefix("urn:plugnproduce:device:"): r.reason for r in refused}
    assert set(reasons) == {*HOSTILE, "silent"}, reasons
    for name, reason in reasons.items():
        assert reason.startswith(f"device {name}"), reason
    assert "Description/Turtle is no text" in reasons["huge-array"]
    assert "Description/TurtleName is no text" in reasons["bad-types"]
    assert "within 15 s" in reasons["silent"]
    assert "BadNoMatch" in reasons["endless-browse"]  # the description is not where the naming rule says
    assert "describes" not in reasons["far-too-large"], reasons  # ended by the transport limits, never parsed
    assert report.outcome == "succeeded", report.fault
