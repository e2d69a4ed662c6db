"""The live cell: devices found by SSDP, described by themselves, plugged and unplugged.

Every Plug'n'Produce device, whatever protocol it is driven over, announces itself as
a UPnP root device and serves its own description (Turtle + Device State Chart) from
the address it was discovered at (see ``docs/upnp.md``). The live cell searches once
at start, then follows ``alive`` and ``byebye`` announcements; each change yields a
:class:`CellChange` with the new cell, so the offered process commands can be
re-inferred at once. Entering the cell waits for the search window, or only until the
``expected`` devices have answered; answers later in the window still plug in.

Anyone can announce a device's (predictable) UDN: each place a UDN is announced at is
tried in turn, one at a time per UDN, until one's description reads; an impostor that
announced first is refused and does not keep the real device out.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import logging
import re
from collections.abc import AsyncIterator, Collection
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal
from urllib.parse import urlparse

from rdflib.term import Node

from plugnproduce.description.loader import device_from, file_of, parse_description
from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import DescriptionError, ProtocolError, ProtocolTimeout, excerpt
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP
from plugnproduce.protocols.upnp import (
    LOOPBACK,
    Advertisement,
    AdvertisementListener,
    DeviceSearch,
    FoundDevice,
    RemoteFiles,
    SearchHit,
    SsdpNetwork,
    UntrustedUrlError,
    UpnpDeviceClient,
    describe,
)
from plugnproduce.protocols.xirp import format_endpoint, parse_endpoint

_LOGGER = logging.getLogger(__name__)

SERVED = Path("/served")
"""Where a discovered device's files are said to be: a name for messages and relative IRIs, never a folder
on disk (a device's chart is only the chart it serves)."""

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
        expected: Collection[str] = (),
    ) -> None:
        self.taxonomy = taxonomy
        self.network = network
        self.name = name
        self.search_timeout = search_timeout
        self.expected = frozenset(expected)
        """Device ids whose answers end the wait at start (none: the whole search window is waited)."""
        self._devices: dict[str, DeviceDescription] = {}
        self._found: dict[str, FoundDevice] = {}
        self._turns: dict[str, tuple[asyncio.Lock, int]] = {}  # UDN → its lock and how many wait for it
        self._plugged = asyncio.Event()
        self._search: asyncio.Task[None] | None = None
        self._changes: asyncio.Queue[CellChange] = asyncio.Queue()
        self._listener = AdvertisementListener(network)
        self._task: asyncio.Task[None] | None = None

    @property
    def cell(self) -> Cell:
        """The devices present now, sorted by id."""
        return Cell(self.name, tuple(sorted(self._devices.values(), key=lambda d: d.id)))

    async def __aenter__(self) -> LiveCell:
        await self._listener.start()
        search = DeviceSearch(self.network, mx=max(1, min(5, int(self.search_timeout))))
        try:
            await search.start()
        except BaseException:
            await self._listener.stop()
            raise
        self._search = asyncio.create_task(self._follow_search(search))
        while not self._search.done() and not self._expected_present():
            self._plugged.clear()
            plugged = asyncio.create_task(self._plugged.wait())
            await asyncio.wait((self._search, plugged), return_when=asyncio.FIRST_COMPLETED)
            plugged.cancel()
        if self._search.done() and (error := self._search.exception()) is not None:
            await self._listener.stop()
            raise error
        self._task = asyncio.create_task(self._follow())
        return self

    def _expected_present(self) -> bool:
        """Whether every expected device is in the cell (never, when none is expected: the window decides)."""
        return bool(self.expected) and self.expected <= {d.id for d in self._devices.values()}

    async def __aexit__(self, *exc_info: object) -> None:
        for task in (self._task, self._search):
            if task is not None:
                task.cancel()
                with contextlib.suppress(asyncio.CancelledError):
                    await task
        await self._listener.stop()

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

    async def _follow_search(self, search: DeviceSearch) -> None:
        """Plug each device that answers the search, in the order they answer, until the window ends."""
        deadline = asyncio.get_running_loop().time() + self.search_timeout
        try:
            while (left := deadline - asyncio.get_running_loop().time()) > 0:
                try:
                    hit = await search.next_hit(left)
                except ProtocolTimeout:
                    break
                await self._plug_advertised(hit)
        finally:
            search.stop()

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

    @contextlib.asynccontextmanager
    async def _turn(self, udn: str) -> AsyncIterator[None]:
        """One place at a time per UDN (a search answer and an alive, or a device and an impostor)."""
        lock, waiting = self._turns.get(udn, (asyncio.Lock(), 0))
        self._turns[udn] = (lock, waiting + 1)
        try:
            async with lock:
                yield
        finally:
            lock, waiting = self._turns[udn]
            if waiting == 1:
                del self._turns[udn]
            else:
                self._turns[udn] = (lock, waiting - 1)

    async def _plug_advertised(self, ad: Advertisement | SearchHit) -> None:
        async with self._turn(ad.udn):
            if ad.udn in self._devices:  # a place announcing this UDN was plugged meanwhile
                return
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
        self._plugged.set()

    async def _fetch(self, found: FoundDevice) -> DeviceDescription:
        """Fetch the device's own description files and read them as any description."""
        async with await UpnpDeviceClient.from_found(found) as client:
            files = await client.fetch_files()
        return read_served(files, found, self.taxonomy)


def _is_served_chart(named: Node, chart: Path) -> bool:
    """Whether a chart a description names is the chart the device served (a NUL, even %00, names no file)."""
    path = file_of(named)
    return "\0" not in str(path) and path.resolve() == chart.resolve()


def read_served(files: RemoteFiles, found: FoundDevice, taxonomy: Taxonomy) -> DeviceDescription:
    """Read the description and chart a device served (fetched already) as any description, from memory.

    The chart must be the one the device serves and an XIRP endpoint must be on the host the
    device was found at; anything else is refused (:class:`DescriptionError`, :class:`ProtocolError`),
    naming the URL the device served the file at.
    """
    folder = SERVED / _safe_name(found.udn)  # names the files for messages and relative IRIs; nothing is written
    ttl = folder / _safe_name(Path(urlparse(files.description_url).path).name or "description.ttl")
    chart = folder / _safe_name(Path(urlparse(files.chart_url).path).name or "chart.scxml")
    try:
        loaded = parse_description(files.description.encode("utf-8"), ttl)
        for named in loaded.graph.objects(None, PNP.stateChart):
            if not _is_served_chart(named, chart):
                raise DescriptionError(f"device {found.udn} names its chart <{excerpt(str(named))}>; expected "
                                       f"the chart it serves ({chart.name})", ttl)
        device = device_from(loaded, taxonomy, charts={chart: files.chart.encode("utf-8")})
    except DescriptionError as exc:  # say where the device serves the file, not the name it was read under
        served = {str(ttl): files.description_url, str(chart): files.chart_url}
        raise DescriptionError(exc.message.replace(str(folder), ""), served.get(exc.file or "", found.location),
                               exc.line) from exc
    if device.protocol == "upnp":  # reached where it was found, whatever its Turtle says
        return replace(device, endpoint=found.location)
    host = urlparse(found.location).hostname  # None: found at no host, so no endpoint is on its host
    named_host, port = parse_endpoint(device.endpoint)
    if host is None or (named_host != host and not (named_host.lower() == "localhost" and _is_loopback(host))):
        raise UntrustedUrlError(f"device {excerpt(device.id)} found at {host or excerpt(found.location)} "
                                f"names XIRP endpoint {excerpt(device.endpoint)} on another host; refused")
    return replace(device, endpoint=format_endpoint(host, port))  # reached where it was found, never by name


def _is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback address (``localhost`` always names this machine)."""
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
