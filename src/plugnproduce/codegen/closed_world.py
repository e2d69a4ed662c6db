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
import dataclasses

from plugnproduce.chartnames import DONE, FAILED
from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.model import PROTOCOLS, Cell, DeviceDescription
from plugnproduce.statechart.io.writer import write_chart
from plugnproduce.statechart.model import (
    Cancel,
    Chart,
    Data,
    Final,
    History,
    Parallel,
    Send,
    State,
    Transition,
    iter_states,
    walk,
)
from plugnproduce.statechart.rename import rename_in

_TARGETS = {DONE: f"controller_{DONE}", FAILED: f"controller_{FAILED}"}


def closed_world_chart(generated: GeneratedTask, cell: Cell) -> bytes:
    """The closed-world simulation chart of a generated task on the devices of ``cell``."""
    task = generated.chart
    controller = copy.deepcopy(next(c for c in task.children if isinstance(c, State) and c.id == "task"))
    controller.id = "controller"
    for node in walk(controller, into_charts=False):
        if isinstance(node, Send) and node.type in PROTOCOLS:
            node.event, node.type, node.target = f"{node.target}.{node.event}", None, None
        elif isinstance(node, Transition):
            node.targets = [_TARGETS.get(t, t) for t in node.targets]
    controller.children += [Final(id=_TARGETS[DONE]), Final(id=_TARGETS[FAILED])]
    world = Parallel(id="world", children=[controller])
    data = copy.deepcopy(task.data)
    for device in sorted(cell.devices, key=lambda d: d.id):
        region, device_data = _device_region(device)
        world.children.append(region)
        data += device_data
    world.transitions = [Transition(event="done.state.controller", cond=f"In('controller_{DONE}')", targets=[DONE]),
                         Transition(event="done.state.controller", targets=[FAILED])]
    root = Chart(name=f"closed-world-{generated.task.name}", initial=["world"], datamodel="python",
                 data=data, children=[world, Final(id=DONE), Final(id=FAILED)])
    return write_chart(root)


def _device_region(device: DeviceDescription) -> tuple[State, list[Data]]:
    """A device's own chart as a region: ids and events prefixed with the device id.

    The device's datamodel joins the chart's, its variables prefixed too, and every expression of the
    device's chart reads and writes the prefixed ones: conditions, ``<assign>``, ``<param>``, ``<log>``,
    ``<data>`` values that read other variables, and ``In()`` on the device's own states
    (:func:`~plugnproduce.statechart.rename.rename_in`).
    """
    prefix = device.id.replace("-", "_")
    variables = {d.id: f"{prefix}__{d.id}" for d in device.chart.data}
    states = {s.id: f"{prefix}__{s.id}" for s in iter_states(device.chart) if s.id}
    data = [dataclasses.replace(copy.deepcopy(d), id=variables[d.id]) for d in device.chart.data]
    for d in data:
        rename_in(d, variables, states)
    region = State(id=f"device_{prefix}", initial=[f"{prefix}__{device.initial}"])
    for state in device.chart.children:
        if not isinstance(state, State | Final):
            continue
        s = copy.deepcopy(state)
        rename_in(s, variables, states)
        for node in walk(s, into_charts=False):
            if isinstance(node, State | Final | Parallel | History | Send) and node.id:
                node.id = f"{prefix}__{node.id}"
            if isinstance(node, State) and node.initial:  # a compound state's initial child
                node.initial = [f"{prefix}__{t}" for t in node.initial]
            if isinstance(node, Transition):
                node.targets = [f"{prefix}__{t}" for t in node.targets]
                node.event = " ".join(f"{device.id}.{e}" for e in node.events) or None
            elif isinstance(node, Send):
                node.event = f"{device.id}.{node.event or ''}"
                node.type = node.target = node.delay = node.delayexpr = None
            elif isinstance(node, Cancel) and node.sendid:
                node.sendid = f"{prefix}__{node.sendid}"
        region.children.append(s)
    return region, data
