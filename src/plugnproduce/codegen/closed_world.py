"""The closed-world simulation chart: the task chart and the device models in one document.

A top-level ``<parallel>`` holds the controller (the Task State Chart's body) and one
region per device running the device's own chart. Only standard SCXML remains: the
controller's protocol requests become plain ``<send>`` events to the same session,
named ``DEVICE.PROTOCOL.request.NAME``; the device regions wait for exactly those,
and their protocol events become ``DEVICE.PROTOCOL.event.NAME``, which the controller
waits for. Device-internal events are prefixed with the device id, and their delays
dropped: the chart simulates the logic, not the timing. Any SCXML interpreter can run
it; it reaches ``done`` when the program works against the device models.
"""

from __future__ import annotations

import copy

from lxml import etree

from plugnproduce.codegen.emit import SCXML_NS, el, to_bytes
from plugnproduce.codegen.task import DONE, FAILED, GeneratedTask
from plugnproduce.description.model import Cell
from plugnproduce.safeio import parse_xml

S = f"{{{SCXML_NS}}}"


def closed_world_chart(generated: GeneratedTask, cell: Cell) -> bytes:
    """The closed-world simulation chart of a generated task on the devices of ``cell``."""
    root = el("scxml", version="1.0", datamodel="python", initial="world", name=f"closed-world-{generated.task.name}")
    world = el("parallel", id="world")
    controller = copy.deepcopy(generated.chart.find(f"{S}state[@id='task']"))
    assert controller is not None  # generate_task always writes it
    controller.set("id", "controller")
    for send in controller.iter(f"{S}send"):
        if send.get("type") in ("xirp", "upnp"):
            send.set("event", f"{send.get('target')}.{send.get('event')}")
            del send.attrib["type"], send.attrib["target"]
    for t in controller.iter(f"{S}transition"):
        if t.get("target") in (DONE, FAILED):
            t.set("target", f"controller_{t.get('target')}")
    controller.append(el("final", id=f"controller_{DONE}"))
    controller.append(el("final", id=f"controller_{FAILED}"))
    world.append(controller)
    for device in sorted(cell.devices, key=lambda d: d.id):
        world.append(_device_region(device.id, device.chart_file, device.initial))
    world.append(el("transition", event="done.state.controller", cond=f"In('controller_{DONE}')", target=DONE))
    world.append(el("transition", event="done.state.controller", target=FAILED))
    root.append(world)
    root.append(el("final", id=DONE))
    root.append(el("final", id=FAILED))
    return to_bytes(root)


def _device_region(device: str, chart_file: str, initial: str) -> etree._Element:
    """A device's own chart as a region: ids and events prefixed with the device id."""
    chart = parse_xml(chart_file).getroot()
    prefix = device.replace("-", "_")
    region = el("state", id=f"device_{prefix}", initial=f"{prefix}__{initial}")
    for state in chart:
        if not isinstance(state.tag, str) or state.tag not in (f"{S}state", f"{S}final"):
            continue
        s = copy.deepcopy(state)
        for node in s.iter():
            if node.get("id"):
                node.set("id", f"{prefix}__{node.get('id')}")
            if node.tag == f"{S}transition":
                if node.get("target"):
                    node.set("target", " ".join(f"{prefix}__{t}" for t in node.get("target", "").split()))
                if node.get("event"):
                    node.set("event", " ".join(f"{device}.{e}" for e in node.get("event", "").split()))
            if node.tag == f"{S}send":
                _localise_send(node, device)
        region.append(s)
    return region


def _localise_send(send: etree._Element, device: str) -> None:
    event = send.get("event", "")
    send.set("event", f"{device}.{event}")
    for attr in ("type", "target", "delay", "delayexpr"):
        send.attrib.pop(attr, None)
