"""What the executor reads from a generated task chart's annotations: per controller state, the device
region it belongs to, the device state it stands for, and whether entering it starts a step."""

from __future__ import annotations

from dataclasses import dataclass

from plugnproduce.statechart import PNP_NS, Chart, Parallel
from plugnproduce.statechart.model import StateNode

_COMMAND, _DEVICE, _DEVICE_STATE = (f"{{{PNP_NS}}}{n}" for n in ("command", "device", "deviceState"))


@dataclass(frozen=True)
class StateInfo:
    """One controller state of the task chart, as the journal tells of it."""

    device: str | None
    device_state: str | None
    command: str | None
    starts_step: bool
    """The state is a step's chart: entering it starts the step the plan's counter names."""


def chart_map(chart: Chart) -> dict[str, StateInfo]:
    """Per controller state: the device region it belongs to, the device state it stands for, its process."""
    out: dict[str, StateInfo] = {}

    def walk(node: StateNode, device: str | None, command: str | None) -> None:
        attrs = node.extra_attrs
        starts = isinstance(node, Parallel) and _COMMAND in attrs
        command = attrs[_COMMAND] if starts else command
        device = attrs.get(_DEVICE, device)
        if node.id:
            out[node.id] = StateInfo(device, attrs.get(_DEVICE_STATE), command, starts)
        for child in getattr(node, "children", ()):
            walk(child, device, command)

    for top in chart.children:
        walk(top, None, None)
    return out
