"""A cell read from a cell file, with plug and unplug done in memory from a catalogue.

It stands in for discovery: plugging a catalogue device adds its description to the
cell, unplugging removes it, and every listener hears about it at once, just as it
will hear about SSDP ``alive`` and ``byebye`` from the live cell.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.hmi.interfaces import CellChangeRefused, CellListener, CellUpdate


class FileCellSource:
    """The devices of a cell file, changed in memory by :meth:`plug` and :meth:`unplug`."""

    def __init__(self, cell: Cell, catalogue: list[DeviceDescription]) -> None:
        self._cell = cell
        known = {d.id: d for d in catalogue}
        known.update({d.id: d for d in cell.devices})  # the cell's own devices can come back after an unplug
        self._known = dict(sorted(known.items()))
        self._listeners: list[CellListener] = []
        self._lock = threading.Lock()

    @property
    def cell(self) -> Cell:
        """The cell as it is now."""
        return self._cell

    def catalogue(self) -> list[DeviceDescription]:
        """The devices that can be plugged in: the catalogue and the cell file's own devices."""
        return list(self._known.values())

    def subscribe(self, listener: CellListener) -> Callable[[], None]:
        """Call ``listener`` on every change; the returned function unsubscribes."""
        with self._lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    async def start(self) -> None:
        """Nothing to follow: the cell changes only through :meth:`plug` and :meth:`unplug`."""

    async def stop(self) -> None:
        """Nothing to stop."""

    async def plug(self, device_id: str) -> None:
        """Plug in a catalogue device."""
        if device_id not in self._known:
            raise KeyError(f"device {device_id!r} (the catalogue has: {', '.join(self._known)})")
        with self._lock:
            if any(d.id == device_id for d in self._cell.devices):
                raise CellChangeRefused(f"device {device_id!r} is in cell {self._cell.name!r} already")
            self._cell = self._cell.with_device(self._known[device_id])
            cell = self._cell
        self._notify(CellUpdate("plug", device_id, cell))

    async def unplug(self, device_id: str) -> None:
        """Unplug a device of the cell."""
        with self._lock:
            if not any(d.id == device_id for d in self._cell.devices):
                present = ", ".join(d.id for d in self._cell.devices) or "none"
                raise KeyError(f"device {device_id!r} in cell {self._cell.name!r} (present: {present})")
            self._cell = self._cell.without(device_id)
            cell = self._cell
        self._notify(CellUpdate("unplug", device_id, cell))

    def _notify(self, update: CellUpdate) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            listener(update)
