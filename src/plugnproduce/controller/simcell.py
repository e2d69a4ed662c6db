"""A simulated cell followed by discovery, as a :class:`~plugnproduce.controller.interfaces.PluggableCellSource`.

The devices of a cell file run their own charts behind XIRP and UPnP servers on a
private loopback SSDP network (:class:`~plugnproduce.sim.cell.SimulatedCell`). The HMI
sees them only through discovery, as it sees real devices: plugging starts a simulated
device, and the cell changes when its ``alive`` arrives; unplugging stops it, and the
cell changes when its ``byebye`` arrives.
"""

from __future__ import annotations

from collections.abc import Callable

from plugnproduce.controller.interfaces import CellChangeRefused
from plugnproduce.controller.livecell import LiveCellSource
from plugnproduce.controller.run import SIMULATED_DISCOVERY_SECONDS, DevicesMissing, default_bin_parts
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.errors import ProtocolTimeout, UnknownName
from plugnproduce.knowledge import Knowledge
from plugnproduce.protocols.interface import LOOPBACK_ADDRESS
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.bin import SimulatedBin
from plugnproduce.sim.cell import SimulatedCell, parse_faults

SEARCH_SECONDS = 0.2
"""The private network is empty until the devices start: the first search need not wait long."""


def _has(device_id: str) -> Callable[[Cell], bool]:
    return lambda cell: any(d.id == device_id for d in cell.devices)


class SimulatedCellSource(LiveCellSource):
    """The devices of ``cell`` simulated, and what discovery sees of them; ``faults`` as ``pnp run --faults``,
    ``bin`` the simulated bin they work on as ``pnp run --bin-parts`` (none: their charts' fixed values).

    Without a ``bin``, a ``default_bin`` is the bin of the runs whose task takes a reported value (a localized
    pose: :func:`plugnproduce.controller.run.default_bin_parts`), as ``pnp run --sim`` gives one; other runs work on
    the charts' fixed values. It is one bin for the session: what one run takes out of it is gone for the next.
    """

    def __init__(self, cell: Cell, catalogue: list[DeviceDescription], faults: str = "",
                 wait: float = SIMULATED_DISCOVERY_SECONDS, knowledge: Knowledge | None = None,
                 bin: SimulatedBin | None = None, default_bin: SimulatedBin | None = None,  # noqa: A002
                 interface: str = LOOPBACK_ADDRESS) -> None:
        """``wait``: seconds a plug, unplug or the start may take until discovery has seen it; ``interface``: the
        address the devices and discovery are on."""
        super().__init__(private_network(interface), name=cell.name, search_timeout=SEARCH_SECONDS,
                         knowledge=knowledge)
        self._wanted = [d.id for d in cell.devices]
        self._wait = wait
        self._default_bin = None if bin is not None else default_bin
        self.sim = SimulatedCell(Cell(cell.name, ()), catalogue=[*catalogue, *cell.devices], network=self.network,
                                 faults=parse_faults(faults, cell.devices), bin=bin)

    def prepare_run(self, task: Task) -> None:
        """Before a run of ``task``: the default bin for a task that takes a reported value, else none (a bin
        given at the start stays)."""
        if self._default_bin is not None:
            self.sim.use_bin(self._default_bin if default_bin_parts(task) is not None else None)

    def catalogue(self) -> list[DeviceDescription]:
        """The devices that can be plugged in: the catalogue and the cell file's own devices."""
        return [self.sim.catalogue[k] for k in sorted(self.sim.catalogue)]

    async def start(self) -> None:
        """Follow discovery, then start the cell file's devices and wait until discovery has seen them all."""
        await super().start()
        for device_id in self._wanted:
            await self.sim.plug(device_id)
        if not await self.wait_until(lambda cell: {d.id for d in cell.devices} >= set(self._wanted), self._wait):
            missing = sorted(set(self._wanted) - {d.id for d in self.cell.devices})
            raise DevicesMissing(f"simulated device(s) {', '.join(missing)} of cell {self.cell.name} "
                                         f"not seen by discovery within {self._wait:g} s")

    async def stop(self) -> None:
        """Stop every simulated device (each says goodbye), then stop following discovery."""
        try:
            await self.sim.stop()
        finally:
            await super().stop()

    async def plug(self, device_id: str) -> None:
        """Start a catalogue device; return once discovery has seen it join."""
        if device_id not in self.sim.catalogue:
            raise UnknownName("device", device_id, self.sim.catalogue, owner="the catalogue")
        if device_id in self.sim.devices:
            raise CellChangeRefused(f"device {device_id!r} is in cell {self.cell.name!r} already")
        await self.sim.plug(device_id)
        if not await self.wait_until(_has(device_id), self._wait):
            raise ProtocolTimeout(f"device {device_id!r} was started but discovery did not see it join "
                                  f"within {self._wait:g} s")

    async def unplug(self, device_id: str) -> None:
        """Stop a device of the cell; return once discovery has seen it leave."""
        if device_id not in self.sim.devices:
            raise UnknownName("device", device_id, self.sim.devices, owner=f"cell {self.cell.name}")
        await self.sim.unplug(device_id)
        if not await self.wait_until(lambda cell: not _has(device_id)(cell), self._wait):
            raise ProtocolTimeout(f"device {device_id!r} was stopped but discovery did not see it leave "
                                  f"within {self._wait:g} s")
