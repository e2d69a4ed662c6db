"""The OPC UA nutrunner's hierarchical PackML chart: ``Running`` around Starting/Execute/Completing, and Abort
written once on the superstate ``Abortable``, taken from however deep the skill is, over OPC UA, as any client
calls it."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from pathlib import Path

from asyncua import Client

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.description.model import DeviceDescription
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua import namespace_for
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT


def _device() -> DeviceDescription:
    return load_device(Path(service.builtin("devices", "screwdriver-ua.ttl")), load_taxonomy())


async def _until(condition: Callable[[], bool], what: str) -> None:
    deadline = asyncio.get_running_loop().time() + WAIT
    while not condition():
        assert asyncio.get_running_loop().time() < deadline, what
        await asyncio.sleep(0.01)


def test_the_chart_is_hierarchical_and_abort_is_written_once() -> None:
    device = _device()
    assert [c.id for c in device.compounds] == ["Abortable", "Running"]
    chart = (Path(service.builtin("devices", "screwdriver-ua.scxml"))).read_text()
    assert chart.count('event="opcua.request.Abort" target="Aborting"') == 2  # the superstate's, and Stopping's
    aborts = {t.source for t in (*device.transitions, *device.stops)
              if t.request is not None and t.request.name == "Abort" and t.target == "Aborting"}
    assert aborts == {"Idle", "Starting", "Execute", "Completing", "Complete", "Stopping", "Stopped"}
    inside = [s for s in device.states if s.id in ("Starting", "Execute", "Completing")]
    assert len(inside) == 3 and all(any(c.endswith("#Screwing") for c in s.concepts) for s in inside)


async def test_a_plain_client_aborts_the_skill_from_inside_running() -> None:
    """asyncua's own client starts the skill, sees it Execute (inside Running) and aborts it there: the
    superstate's Abort leads to Aborting, then Aborted; Reset returns to Idle."""
    async with SimulatedDevice(_device()) as sim, Client(sim.endpoint, timeout=WAIT) as client:
        ns = await client.get_namespace_index(namespace_for("screwdriver-ua"))
        device = await client.nodes.objects.get_child(f"{ns}:screwdriver-ua")
        state = await device.get_child(f"{ns}:State")
        await device.call_method(f"{ns}:Start", 3.0)
        await _until(lambda: sim.state == "Execute", "the skill did not execute")
        assert await state.read_value() == "Execute"
        await device.call_method(f"{ns}:Abort")
        await _until(lambda: sim.state == "Aborted", "the skill did not abort")
        assert await state.read_value() == "Aborted"
        await device.call_method(f"{ns}:Reset")
        await _until(lambda: sim.state == "Idle", "the skill did not reset")
