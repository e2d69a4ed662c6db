"""The range of a value a device reports: what a producing device promises about its outputs.

A device declares it in its Device State Chart, on the ``<param>`` of the event that carries the
value, with the attributes of the device contracts: ``pnp:maxReach`` (metres: how far from the
robot's base a reported pose's position may lie), ``pnp:minValue``, ``pnp:maxValue`` and ``pnp:unit``
for a number::

    <send event="upnp.event.PartLocalized" type="upnp">
      <param name="part_pose" expr="part_pose" pnp:maxReach="1.2"/>
    </send>

With it, the check can prove that a later step's request taking the value keeps its device's
contract; without it, the value is checked at run time only.
"""

from __future__ import annotations

import math

from plugnproduce.deferred import dataclass
from plugnproduce.description.model import Command, DeviceDescription, Where
from plugnproduce.description.quantities.units import unit_known
from plugnproduce.errors import DescriptionError
from plugnproduce.statechart.model import PNP_NS, Param, Send, walk

_ATTRS = {"maxReach": "reach", "minValue": "minimum", "maxValue": "maximum"}


@dataclass(frozen=True)
class OutputRange:
    """What a device promises about a value it reports."""

    output: str
    unit: str = ""
    minimum: float | None = None
    maximum: float | None = None
    reach: float | None = None
    where: Where | None = None

    @property
    def declared(self) -> bool:
        """Whether it promises anything."""
        return any(v is not None for v in (self.minimum, self.maximum, self.reach))


def output_ranges(device: DeviceDescription) -> dict[str, OutputRange]:
    """The ranges the device's chart declares for the values its events carry, by value name."""
    out: dict[str, OutputRange] = {}
    for node in walk(device.chart):
        command = Command.parse(node.event or "") if isinstance(node, Send) else None
        if not isinstance(node, Send) or command is None or command.kind != "event":
            continue
        for param in node.params:
            found = _range(device, param)
            if found.declared:
                out[param.name] = found
    return out


def _range(device: DeviceDescription, param: Param) -> OutputRange:
    where = Where(device.chart_file, param.line)
    numbers: dict[str, float] = {}
    for attr, field in _ATTRS.items():
        text = param.extra_attrs.get(f"{{{PNP_NS}}}{attr}")
        if text is None:
            continue
        try:
            number = float(text) if text.strip().isascii() else math.nan
        except ValueError:
            number = math.nan
        if not math.isfinite(number) or (attr == "maxReach" and number <= 0):
            raise DescriptionError(f"value {param.name}: pnp:{attr} is {text[:40]!r}; expected a finite "
                                   f"{'positive ' if attr == 'maxReach' else ''}number", device.chart_file, param.line)
        numbers[field] = number
    unit = param.extra_attrs.get(f"{{{PNP_NS}}}unit", "")
    if not unit_known(unit):
        raise DescriptionError(f"value {param.name}: unknown unit {unit[:40]!r}; expected a unit such as \"N\" or "
                               "\"mm\"", device.chart_file, param.line)
    return OutputRange(param.name, unit, numbers.get("minimum"), numbers.get("maximum"), numbers.get("reach"), where)
