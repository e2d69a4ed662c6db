"""The values a device reports with its state: what teach-in reads from it.

A device declares them in its Device State Chart, on the ``<data>`` that holds the value, with the
quantity it is (``pnp:quantity``, a quantity of the ontology by local name) and, for a number, its
unit (``pnp:unit``)::

    <data id="pose" expr="[0.40, 0.00, 0.60, 0, 180, 0]" pnp:quantity="TargetPose"/>

The device answers its state query with the state and each such value, named after the quantity, over
each protocol: a result of XIRP's ``state`` response (``docs/xirp.md``, *state*), an out-argument of UPnP's
``GetDeviceState`` holding JSON (``docs/upnp.md``), a variable beside OPC UA's ``State`` (``docs/opcua.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

from plugnproduce.description.model import DeviceDescription, Where
from plugnproduce.statechart.model import PNP_NS, Data, walk

QUANTITY = f"{{{PNP_NS}}}quantity"
UNIT = f"{{{PNP_NS}}}unit"


@dataclass(frozen=True)
class ReportedValue:
    """A value a device reports with its state."""

    quantity: str
    """The quantity's local name (``TargetPose``): the name the value travels under."""
    variable: str
    """The chart's datamodel variable that holds it."""
    unit: str = ""
    where: Where | None = None


def reported_values(device: DeviceDescription) -> dict[str, ReportedValue]:
    """The values the device's chart declares it reports with its state, by quantity."""
    out: dict[str, ReportedValue] = {}
    for node in walk(device.chart):
        if isinstance(node, Data) and (quantity := node.extra_attrs.get(QUANTITY)):
            out[quantity] = ReportedValue(quantity, node.id, node.extra_attrs.get(UNIT, ""),
                                          Where(device.chart_file, node.line))
    return out
