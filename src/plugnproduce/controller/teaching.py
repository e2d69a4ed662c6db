"""Teach-in (paper section 5.3): read a value from a device by its state query and hold it to its contracts.

The operator guides the device (a robot to a pose); :func:`teach` finds the device by discovery, asks its state
and the values it reports with it, and judges the one asked for (:func:`plugnproduce.service.judge_taught`).
``pnp teach`` prints it; the HMI's step dialog puts it into a parameter, where the check holds it to the bound
device's contract again like any typed value.
"""

from __future__ import annotations

from pathlib import Path

from plugnproduce.controller.run import DISCOVERY_SECONDS, find_devices
from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import ProtocolError
from plugnproduce.knowledge import Knowledge
from plugnproduce.service import Taught, cell_and_knowledge, judge_taught, reported_value


async def teach(device_id: str, quantity: str, cell_or_path: Cell | str | Path, knowledge: Knowledge | None = None,
                discovery_timeout: float = DISCOVERY_SECONDS) -> Taught:
    """The value ``quantity`` that device ``device_id`` of the cell reports now, judged against its contracts;
    the device is found on the network ``PNP_SSDP_PORT`` names."""
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.upnp import network_from_env

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    device = the_cell.device(device_id)
    reported_value(device, quantity)  # an unknown quantity is bad input before the network is asked
    async with LiveCell(k.taxonomy, network=network_from_env(), name=the_cell.name, expected=[device_id]) as live:
        found = (await find_devices(live, [device_id], discovery_timeout)).device(device_id)
    return await read_taught(found, quantity)


async def read_taught(device: DeviceDescription, quantity: str) -> Taught:
    """Read and judge ``quantity`` from a device at its real endpoint (the HMI's cell source knows it)."""
    from plugnproduce.executor.links import query_report

    reported_value(device, quantity)  # one it does not report is bad input, before the device is asked
    state, values = await query_report(device, device.command_timeout)
    if quantity not in values:
        raise ProtocolError(f"device {device.id} did not report {quantity} with its state "
                            f"(it reported {', '.join(sorted(values)) or 'nothing but its state'})")
    value = values[quantity]
    return judge_taught(device, quantity, list(value) if isinstance(value, tuple) else value, state)
