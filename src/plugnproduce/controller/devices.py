"""The devices on the network for ``pnp discover`` and ``pnp sim``: the live cell discovery finds, and a
simulated cell run under a control address.

Each function imports the network stack when it is called: ``pnp sim plug`` needs only the control channel.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from plugnproduce.description.model import Cell, DeviceDescription
    from plugnproduce.discovery import LiveCell
    from plugnproduce.knowledge import Knowledge
    from plugnproduce.sim.cell import SimulatedCell


def discovery(knowledge: Knowledge, *, search_timeout: float, expected: Collection[str] = (),
              expected_count: int | None = None, quiet: float | None = None, interface: str | None = None) -> LiveCell:
    """The cell as discovery sees it on ``interface`` (an address) and the SSDP port ``PNP_SSDP_PORT`` names,
    followed while the context is open; the search at its start waits for the ``expected`` devices,
    ``expected_count`` of them, or ``quiet`` seconds without news, within ``search_timeout``."""
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.upnp import network_from_env

    return LiveCell(knowledge.taxonomy, network=network_from_env(interface), search_timeout=search_timeout,
                    expected=expected, expected_count=expected_count, quiet=quiet)


def simulated_cell(cell: Cell, catalogue: list[DeviceDescription], knowledge: Knowledge, faults: str = "",
                   bin_parts: int | None = None, bin_seed: int = 0, interface: str | None = None,
                   speed: float = 1.0) -> SimulatedCell:
    """The devices of ``cell`` simulated on ``interface`` (an address) and the SSDP port ``PNP_SSDP_PORT`` names,
    ``catalogue`` the devices that may be plugged in later, with ``faults`` (``pnp run --faults``), on a bin of
    ``bin_parts`` parts if given, ``speed`` times faster than real time."""
    from plugnproduce.protocols.upnp import network_from_env
    from plugnproduce.sim.bin import SimulatedBin
    from plugnproduce.sim.cell import SimulatedCell, parse_faults

    return SimulatedCell(cell, catalogue=catalogue, network=network_from_env(interface),
                         faults=parse_faults(faults, cell.devices), taxonomy=knowledge.taxonomy,
                         bin=SimulatedBin(bin_parts, bin_seed) if bin_parts is not None else None, speed=speed)


async def run_simulated(sim: SimulatedCell, state_file: Path | None, echo: Callable[[str], None]) -> None:
    """``pnp sim up``: run the cell and its control channel until cancelled, its address recorded in
    ``state_file`` (default: the user's state folder)."""
    from plugnproduce.sim import control
    from plugnproduce.sim.cell import run_simulated_cell

    await run_simulated_cell(sim, state_file or control.default_state_file(), echo=echo)


def control_address() -> tuple[str, int]:
    """The control address of the simulated cell started last."""
    from plugnproduce.sim import control

    return control.read_state()


async def control_request(address: tuple[str, int], op: str, device: str = "") -> list[str]:
    """Ask the simulated cell at ``address`` to ``plug`` or ``unplug`` ``device``; the devices running after."""
    from plugnproduce.sim import control

    return await control.request(address, op, device)
