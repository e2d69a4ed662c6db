"""The live cell: devices found by SSDP, described by themselves, plugged and unplugged.

Every Plug'n'Produce device, whatever protocol it is driven over, announces itself as
a UPnP root device and serves its own description (Turtle + Device State Chart) from
the address it was discovered at (see ``docs/upnp.md``). The live cell searches once
at start, then follows ``alive`` and ``byebye`` announcements; each change yields a
:class:`CellChange` with the new cell, so the offered process commands can be
re-inferred at once.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import re
import shutil
import tempfile
from collections.abc import AsyncIterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal
from urllib.parse import urlparse

from plugnproduce.description.loader import file_of, load_device, read_description
from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import DescriptionError, ProtocolError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP
from plugnproduce.protocols.upnp import (
    LOOPBACK,
    Advertisement,
    AdvertisementListener,
    FoundDevice,
    RemoteFiles,
    SsdpNetwork,
    UntrustedUrlError,
    UpnpDeviceClient,
    describe,
    discover,
)
from plugnproduce.protocols.xirp import parse_endpoint
from plugnproduce.safeio import excerpt

_LOGGER = logging.getLogger(__name__)

CONFIRM_TIMEOUT = 1.0
"""Seconds a device's address is given to answer before its byebye is believed."""


def _safe_name(name: str) -> str:
    """A file name that stays inside its folder, from anything a device sends."""
    cleaned = re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip(".")
    return cleaned[:100] or "unnamed"


@dataclass(frozen=True)
class CellChange:
    """A device was plugged in, unplugged, or refused; ``cell`` is the cell after the change."""

    kind: Literal["plug", "unplug", "refused"]
    device: str
    cell: Cell
    reason: str = ""


class LiveCell:
    """The cell as discovery sees it, kept up to date while the context is open."""

    def __init__(
        self,
        taxonomy: Taxonomy,
        *,
        network: SsdpNetwork = LOOPBACK,
        name: str = "live",
        search_timeout: float = 1.0,
    ) -> None:
        self.taxonomy = taxonomy
        self.network = network
        self.name = name
        self.search_timeout = search_timeout
        self._devices: dict[str, DeviceDescription] = {}
        self._found: dict[str, FoundDevice] = {}
        self._changes: asyncio.Queue[CellChange] = asyncio.Queue()
        self._listener = AdvertisementListener(network)
        self._task: asyncio.Task[None] | None = None
        self._workdir = Path(tempfile.mkdtemp(prefix="pnp-live-"))

    @property
    def cell(self) -> Cell:
        """The devices present now, sorted by id."""
        return Cell(self.name, tuple(sorted(self._devices.values(), key=lambda d: d.id)))

    async def __aenter__(self) -> LiveCell:
        await self._listener.start()
        found = await discover(self.search_timeout, network=self.network)
        for device in sorted(found.devices, key=lambda d: d.udn):
            await self._plug(device)
        for refusal in found.refused:
            self._publish(CellChange("refused", refusal.udn, self.cell, refusal.reason))
        self._task = asyncio.create_task(self._follow())
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task
        await self._listener.stop()
        shutil.rmtree(self._workdir, ignore_errors=True)

    async def changes(self) -> AsyncIterator[CellChange]:
        """Every change from now on (and the ones not yet taken), as they happen."""
        while True:
            yield await self._changes.get()

    async def next_change(self, timeout: float | None = None) -> CellChange:
        """The next change, waiting at most ``timeout`` seconds."""
        return await asyncio.wait_for(self._changes.get(), timeout)

    def _publish(self, change: CellChange) -> None:
        if change.reason:  # one line, whatever a device made the reason of
            change = replace(change, reason=" ".join(change.reason.split())[:500])
        self._changes.put_nowait(change)

    async def _follow(self) -> None:
        while True:
            ad = await self._listener.next(None)
            try:
                if ad.alive and ad.udn not in self._devices:
                    await self._plug_advertised(ad)
                elif not ad.alive and ad.udn in self._devices:
                    await self._unplug_confirmed(ad.udn)
            except Exception as exc:  # noqa: BLE001 - one device's defect must never stop following the others
                _LOGGER.warning("device %s: %s: %s", ad.udn, type(exc).__name__, exc)
                self._publish(CellChange("refused", ad.udn, self.cell, f"{type(exc).__name__}: {exc}"))

    async def _unplug_confirmed(self, udn: str) -> None:
        """Unplug on a byebye only if the device's own address confirms it is gone (a byebye may be spoofed)."""
        found = self._found[udn]
        try:
            await describe(Advertisement(udn, True, found.location, found.source_host), timeout=CONFIRM_TIMEOUT)
        except ProtocolError:
            device = self._devices.pop(udn)
            del self._found[udn]
            self._publish(CellChange("unplug", device.id, self.cell))
            return
        _LOGGER.warning("byebye for %s ignored: the device still answers at %s", udn, found.location)

    async def _plug_advertised(self, ad: Advertisement) -> None:
        try:
            found = await describe(ad)
        except ProtocolError as exc:
            self._publish(CellChange("refused", ad.udn, self.cell, str(exc)))
            return
        await self._plug(found)

    async def _plug(self, found: FoundDevice) -> None:
        try:
            device = await self._fetch(found)
        except (ProtocolError, DescriptionError) as exc:
            self._publish(CellChange("refused", found.udn, self.cell, str(exc)))
            return
        except Exception as exc:  # noqa: BLE001 - whatever a device sends, it costs only that device
            reason = f"its description cannot be read ({type(exc).__name__}: {exc})"
            self._publish(CellChange("refused", found.udn, self.cell, reason))
            return
        self._devices[found.udn] = device
        self._found[found.udn] = found
        self._publish(CellChange("plug", device.id, self.cell))

    async def _fetch(self, found: FoundDevice) -> DeviceDescription:
        """Fetch the device's own description files and read them as any description."""
        async with await UpnpDeviceClient.from_found(found) as client:
            files = await client.fetch_files()
        return read_served(files, found, self._workdir / _safe_name(found.udn), self.taxonomy)


def read_served(files: RemoteFiles, found: FoundDevice, folder: Path, taxonomy: Taxonomy) -> DeviceDescription:
    """Read the description and chart a device served (fetched already) in ``folder``, as any description.

    The chart must be the one the device serves and an XIRP endpoint must be on the host the
    device was found at; anything else is refused (:class:`DescriptionError`, :class:`ProtocolError`).
    """
    folder.mkdir(exist_ok=True)
    ttl = folder / _safe_name(Path(urlparse(files.description_url).path).name or "description.ttl")
    ttl.write_text(files.description, encoding="utf-8")
    chart = folder / _safe_name(Path(urlparse(files.chart_url).path).name or "chart.scxml")
    chart.write_text(files.chart, encoding="utf-8")
    for named in read_description(ttl).graph.objects(None, PNP.stateChart):
        if file_of(named).resolve() != chart.resolve():  # a chart elsewhere (a local file, another host)
            raise DescriptionError(f"device {found.udn} names its chart <{excerpt(str(named))}>; expected the "
                                   f"chart it serves ({chart.name})")
    device = load_device(ttl, taxonomy)
    if device.protocol == "upnp":  # reached where it was found, whatever its Turtle says
        return replace(device, endpoint=found.location)
    host = urlparse(found.location).hostname
    if parse_endpoint(device.endpoint)[0] != host:
        raise UntrustedUrlError(f"device {excerpt(device.id)} found at {host} names XIRP endpoint "
                                f"{excerpt(device.endpoint)} "
                                "on another host; refused")
    return device
