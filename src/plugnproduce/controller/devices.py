"""The devices on the network for ``pnp discover`` and ``pnp sim``: the live cell discovery finds, and a
simulated cell run under a control address.

Each function imports the network stack when it is called: ``pnp sim plug`` needs only the control channel.
"""

from __future__ import annotations

import contextlib
from collections.abc import AsyncIterator, Callable, Collection
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from plugnproduce.description.model import Cell, DeviceDescription
    from plugnproduce.discovery import LiveCell
    from plugnproduce.knowledge import Knowledge
    from plugnproduce.sim.cell import SimulatedCell


@contextlib.asynccontextmanager
async def discovery(knowledge: Knowledge, *, search_timeout: float, expected: Collection[str] = (),
                    expected_count: int | None = None, quiet: float | None = None, interface: str | None = None,
                    lds: str | None = None, serve_lds: int | None = None,
                    echo: Callable[[str], None] | None = None) -> AsyncIterator[LiveCell]:
    """The cell as discovery sees it on ``interface`` (an address) and the SSDP port ``PNP_SSDP_PORT`` names,
    followed while the context is open; the search at its start waits for the ``expected`` devices,
    ``expected_count`` of them, or ``quiet`` seconds without news, within ``search_timeout``; the OPC UA devices
    registered with the Local Discovery Server ``lds`` (else ``PNP_LDS``, else none) are in it too. With
    ``serve_lds`` (a port, 0: any free one) the controller runs that LDS itself, on ``interface``, for the devices
    to register with (its endpoint told to ``echo`` before the search)."""
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.opcua.spec import chosen_lds
    from plugnproduce.protocols.upnp import network_from_env

    network = network_from_env(interface)
    async with contextlib.AsyncExitStack() as stack:
        if serve_lds is not None:
            lds = await serve_lds_on(stack, network.interface, serve_lds)
            if echo is not None:
                echo(lds)
        async with LiveCell(knowledge.taxonomy, network=network, search_timeout=search_timeout, expected=expected,
                            expected_count=expected_count, quiet=quiet, lds=chosen_lds(lds)) as live:
            yield live


async def serve_lds_on(stack: contextlib.AsyncExitStack, address: str, port: int) -> str:
    """A Local Discovery Server on ``address``:``port``, stopped with ``stack``; its endpoint."""
    from plugnproduce.protocols.opcua.discovery import LocalDiscoveryServer

    server = await stack.enter_async_context(LocalDiscoveryServer(address, port))
    assert server.endpoint is not None
    return server.endpoint


def simulated_cell(cell: Cell, catalogue: list[DeviceDescription], knowledge: Knowledge, faults: str = "",
                   bin_parts: int | None = None, bin_seed: int = 0, interface: str | None = None,
                   speed: float = 1.0, lds: str | None = None) -> SimulatedCell:
    """The devices of ``cell`` simulated on ``interface`` (an address) and the SSDP port ``PNP_SSDP_PORT`` names,
    ``catalogue`` the devices that may be plugged in later, with ``faults`` (``pnp run --faults``), on a bin of
    ``bin_parts`` parts if given, ``speed`` times faster than real time; its OPC UA devices register with the
    Local Discovery Server ``lds`` if given."""
    from plugnproduce.protocols.upnp import network_from_env
    from plugnproduce.sim.bin import SimulatedBin
    from plugnproduce.sim.cell import SimulatedCell, parse_faults

    return SimulatedCell(cell, catalogue=catalogue, network=network_from_env(interface),
                         faults=parse_faults(faults, cell.devices), taxonomy=knowledge.taxonomy,
                         bin=SimulatedBin(bin_parts, bin_seed) if bin_parts is not None else None, speed=speed,
                         lds=lds)


async def run_simulated(sim: SimulatedCell, state_file: Path | None, echo: Callable[[str], None],
                        serve_lds: int | None = None) -> None:
    """``pnp sim up``: run the cell and its control channel until cancelled, its address recorded in
    ``state_file`` (default: the user's state folder); with ``serve_lds`` (a port, 0: any free one) beside a
    Local Discovery Server on the cell's address, which its OPC UA devices register with."""
    from plugnproduce.sim import control
    from plugnproduce.sim.cell import run_simulated_cell

    async with contextlib.AsyncExitStack() as stack:
        if serve_lds is not None:
            sim.lds = await serve_lds_on(stack, sim.network.interface, serve_lds)
            echo(f"{'lds':16} opcua {sim.lds}")
        await run_simulated_cell(sim, state_file or control.default_state_file(), echo=echo)


def control_address() -> tuple[str, int]:
    """The control address of the simulated cell started last."""
    from plugnproduce.sim import control

    return control.read_state()


async def control_request(address: tuple[str, int], op: str, device: str = "") -> list[str]:
    """Ask the simulated cell at ``address`` to ``plug`` or ``unplug`` ``device``; the devices running after."""
    from plugnproduce.sim import control

    return await control.request(address, op, device)
