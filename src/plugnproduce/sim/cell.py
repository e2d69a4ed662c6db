"""The simulated cell: every device of a cell file running its own chart, plugged and unplugged at run time.

Faults are injected per device with a spec such as ``gripper:drop-response:Close``
(see :func:`parse_faults`); they apply to devices driven over XIRP.
"""

from __future__ import annotations

import asyncio
import re
from collections.abc import Callable, Iterable
from pathlib import Path

from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import DescriptionError, PlugNProduceError, ProtocolError, UnknownName
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.protocols import upnp, xirp
from plugnproduce.sim import control
from plugnproduce.sim.bin import SimulatedBin
from plugnproduce.sim.device import SimulatedDevice


class FaultSpecError(PlugNProduceError):
    """A ``--faults`` spec that cannot be read."""


def parse_faults(spec: str, devices: Iterable[DeviceDescription]) -> dict[str, xirp.Faults]:
    """Faults per device from ``DEVICE:KIND[:NAME[:SECONDS]]`` items separated by commas.

    KIND is one of ``drop-response`` (no answer), ``error-response``, ``malformed-response``,
    ``disconnect``, ``drop-event``, ``delay-event`` (SECONDS late), ``duplicate-event`` and
    ``malformed-event``; NAME limits it to one request or event. Each fires once.
    """
    known = {d.id: d for d in devices}
    faults: dict[str, xirp.Faults] = {}
    for item in filter(None, (part.strip() for part in spec.split(","))):
        parts = item.split(":")
        if len(parts) < 2 or len(parts) > 4:
            raise FaultSpecError(f"--faults {item!r}: expected DEVICE:KIND[:NAME[:SECONDS]]")
        device, kind = parts[0], parts[1]
        if device not in known:
            raise FaultSpecError(f"--faults {item!r}: {UnknownName('device', device, known, owner='the cell')}")
        if known[device].protocol != "xirp":
            raise FaultSpecError(f"--faults {item!r}: faults are injected over XIRP; {device} speaks "
                                 f"{known[device].protocol}")
        if kind not in set(xirp.FaultKind):
            raise FaultSpecError(f"--faults {item!r}: unknown kind {kind!r}; expected one of "
                                 f"{', '.join(xirp.FaultKind)}")
        name = parts[2] if len(parts) > 2 and parts[2] else None
        delay = _seconds(item, parts[3]) if len(parts) > 3 else 0.0
        try:
            faults.setdefault(device, xirp.Faults()).add(kind, name, delay=delay)
        except (ValueError, xirp.MessageError) as exc:
            raise FaultSpecError(f"--faults {item!r}: {exc}") from None
    return faults


MAX_FAULT_SECONDS = 3600.0
"""Longest delay a fault may inject."""


def _seconds(item: str, text: str) -> float:
    """A fault's SECONDS: a plain decimal number from 0 to :data:`MAX_FAULT_SECONDS` (no ``nan``, ``inf``, ``-1``)."""
    if not re.fullmatch(r"[0-9]+(?:\.[0-9]*)?|\.[0-9]+", text.strip()) or float(text) > MAX_FAULT_SECONDS:
        raise FaultSpecError(f"--faults {item!r}: SECONDS must be a number from 0 to {MAX_FAULT_SECONDS:g}; "
                             f"found {text!r}")
    return float(text)


class SimulatedCell:
    """The devices of a cell, simulated; ``catalogue`` holds the devices that may be plugged in later."""

    def __init__(self, cell: Cell, *, catalogue: Iterable[DeviceDescription] = (),
                 network: upnp.SsdpNetwork = upnp.LOOPBACK, faults: dict[str, xirp.Faults] | None = None,
                 taxonomy: Taxonomy | None = None, bin: SimulatedBin | None = None,  # noqa: A002
                 speed: float = 1.0) -> None:
        """``taxonomy`` reads device description files plugged in by path (default: the built-in ontology);
        ``bin`` is the simulated bin the devices work on (none: they report their charts' fixed values);
        ``speed`` how much faster than real time the devices work (their durations divided by it)."""
        self.speed = speed
        self.cell = cell
        self.bin = bin
        self.taxonomy = taxonomy
        self.network = network
        self.faults = faults or {}
        self.catalogue = {d.id: d for d in (*catalogue, *cell.devices)}
        self.devices: dict[str, SimulatedDevice] = {}

    def use_bin(self, bin: SimulatedBin | None) -> None:  # noqa: A002
        """Let the devices work on ``bin`` from their next request on (none: their charts' fixed values), and
        the devices plugged in later too."""
        self.bin = bin
        for device in self.devices.values():
            device.bin = bin

    async def __aenter__(self) -> SimulatedCell:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.stop()

    async def start(self) -> None:
        """Start every device of the cell."""
        for device in self.cell.devices:
            await self.plug(device.id)

    async def stop(self) -> None:
        """Stop every device (each says goodbye)."""
        for device_id in list(self.devices):
            await self.unplug(device_id)

    async def plug(self, device_id: str) -> list[str]:
        """Start a catalogue device, or the device a description file describes; returns the running devices."""
        if device_id.endswith(".ttl"):
            device_id = self._add_file(Path(device_id))
        if device_id in self.devices:
            raise ProtocolError(f"device {device_id!r} is plugged in already")
        if device_id not in self.catalogue:
            raise ProtocolError(f"no device {device_id!r} to plug in; known: {', '.join(sorted(self.catalogue))}; "
                                "a library's device needs the cell started with it: "
                                "pnp --library LIBRARY sim up CELL")
        device = SimulatedDevice(self.catalogue[device_id], network=self.network, faults=self.faults.get(device_id),
                                 bin=self.bin, speed=self.speed)
        await device.start()
        self.devices[device_id] = device
        return sorted(self.devices)

    def _add_file(self, path: Path) -> str:
        from plugnproduce.description.loader import load_device  # reads RDF: only when a file is plugged
        from plugnproduce.ontology.taxonomy import load_taxonomy

        try:
            device = load_device(path, self.taxonomy or load_taxonomy())
        except DescriptionError as exc:
            raise ProtocolError(exc.location_message() + _library_hint(path)) from exc
        known = self.catalogue.setdefault(device.id, device)
        if known.where != device.where:
            raise ProtocolError(f"{device.where}: device id {device.id!r} is already the catalogue's {known.where}")
        return device.id

    async def unplug(self, device_id: str) -> list[str]:
        """Stop a running device; returns the running devices."""
        device = self.devices.pop(device_id, None)
        if device is None:
            raise ProtocolError(f"device {device_id!r} is not plugged in; running: {', '.join(sorted(self.devices))}")
        await device.stop()
        return sorted(self.devices)

    async def control(self, op: str, device_id: str) -> list[str]:
        """Answer a ``pnp sim plug/unplug`` request (see :mod:`plugnproduce.sim.control`)."""
        if op == "plug":
            return await self.plug(device_id)
        if op == "unplug":
            return await self.unplug(device_id)
        if op == "list":
            return sorted(self.devices)
        raise ProtocolError(f"unknown operation {op!r}; expected plug, unplug or list")


def _library_hint(path: Path) -> str:
    """For a device file of a library (``LIB/devices/x.ttl`` beside ``LIB/ontology``): how to start a cell
    that knows the library's terms."""
    library = path.resolve().parent.parent
    if path.resolve().parent.name != "devices" or not (library / "ontology").is_dir():
        return ""
    return f"; the cell was started without its library: start it with pnp --library {library} sim up CELL"


async def run_simulated_cell(sim: SimulatedCell, state_file: Path, echo: Callable[[str], None]) -> None:
    """``pnp sim up``: run the cell and its control channel until cancelled (Ctrl-C)."""
    server = control.ControlServer(sim.control)
    async with sim:
        await server.start()
        server.write_state(state_file)
        for device in sim.devices.values():
            echo(f"{device.id:16} {device.description.protocol:5} {device.endpoint}")
        host, port = server.address
        echo(f"simulated cell {sim.cell.name} is up (control {host}:{port}); Ctrl-C stops it")
        try:
            await asyncio.Event().wait()
        finally:
            await server.stop()
            state_file.unlink(missing_ok=True)
