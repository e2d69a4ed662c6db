"""The values a device's protocol events carry, read from its chart."""

from __future__ import annotations

from plugnproduce.description.model import Command, DeviceDescription
from plugnproduce.statechart.model import Send, walk


def event_payloads(device: DeviceDescription) -> dict[str, list[str]]:
    """The values each protocol event of the chart carries (the names of its ``<param>`` elements)."""
    out: dict[str, list[str]] = {}
    for node in walk(device.chart):
        if isinstance(node, Send) and node.event is not None and node.params:
            command = Command.parse(node.event)
            if command is not None and command.kind == "event":
                names = out.setdefault(command.name, [])
                names.extend(p.name for p in node.params if p.name not in names)
    return out
