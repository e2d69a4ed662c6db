"""The live cell: devices found by SSDP, described by themselves, plugged and unplugged.

Every Plug'n'Produce device, whatever protocol it is driven over, announces itself as
a UPnP root device and serves its own description (Turtle + Device State Chart) from
the address it was discovered at (see ``docs/upnp.md``). The live cell searches once
at start, then follows ``alive`` and ``byebye`` announcements; each change yields a
:class:`CellChange` with the new cell, so the offered process commands can be
re-inferred at once. Entering the cell waits for the search window, or only until the
``expected`` devices have answered, or until the answers settle (``quiet``); answers later in
the window still plug in.

Each device is read on its own, concurrently with the others, within its own time budget
(``device_budget``: description and chart together) and the size limit of every file: a device
that hangs, answers a byte at a time or serves 100 MB costs only itself. Every device refused is
kept in :attr:`LiveCell.refused` with its URL and the reason, until it is plugged; one refused for
a timeout is tried again on its next announcement.

Anyone can announce a device's (predictable) UDN: each place a UDN is announced at is
tried in turn, one at a time per UDN, until one's description reads; an impostor that
announced first is refused and does not keep the real device out.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import AsyncIterator, Collection, Coroutine
from dataclasses import dataclass, replace
from typing import Literal

from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.discovery.served import read_served
from plugnproduce.errors import DescriptionError, ProtocolError, ProtocolTimeout, excerpt
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.protocols.opcua import spec as opcua_spec
from plugnproduce.protocols.upnp import (
    LOOPBACK,
    Advertisement,
    AdvertisementListener,
    DeviceSearch,
    FoundDevice,
    Refusal,
    SearchHit,
    SsdpNetwork,
    UpnpDeviceClient,
    describe,
)

_LOGGER = logging.getLogger(__name__)

CONFIRM_TIMEOUT = 1.0
"""Seconds a device's address is given to answer before its byebye is believed."""

MAX_REFUSED = 100
"""Refused devices kept for :attr:`LiveCell.refused` (the latest)."""

LDS_POLL = 1.0
"""Seconds between two questions (FindServers) to the Local Discovery Server, when one is given."""

DEVICE_BUDGET = 15.0
"""Seconds reading one discovered device (its UPnP description, Turtle description and chart) may take in all."""


@dataclass(frozen=True)
class CellChange:
    """A device was plugged in, unplugged, or refused; ``cell`` is the cell after the change."""

    kind: Literal["plug", "unplug", "refused"]
    device: str
    cell: Cell
    reason: str = ""
    location: str = ""
    """For a refused device: the URL it was announced at."""


@dataclass(frozen=True)
class RefusedDevice:
    """A device that announced itself but was not taken into the cell: its UDN, URL and why."""

    udn: str
    location: str
    reason: str


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
        expected_count: int | None = None,
        quiet: float | None = None,
        device_budget: float = DEVICE_BUDGET,
        lds: str | None = None,
    ) -> None:
        """``lds``: a Local Discovery Server (``opc.tcp://HOST:PORT``) whose registered OPC UA devices are in
        the cell too, asked every :data:`LDS_POLL` seconds (a device no longer registered is unplugged)."""
        self.taxonomy = taxonomy
        self.network = network
        self.name = name
        self.search_timeout = search_timeout
        self.expected = frozenset(expected)
        """Device ids whose answers end the wait at start (none: the whole search window is waited)."""
        self.expected_count = expected_count
        """As many devices as end the wait at start (None: not so)."""
        self.quiet = quiet
        """Seconds without news (no answer, no device read) that end the wait at start (None: not so)."""
        self.device_budget = device_budget
        self.refused: dict[str, RefusedDevice] = {}
        """Devices refused and not plugged since, by UDN (the last place and reason of each)."""
        self._devices: dict[str, DeviceDescription] = {}
        self._found: dict[str, FoundDevice] = {}
        self._readings: set[asyncio.Task[None]] = set()
        self._news = 0.0  # loop time of the last answer, plug or refusal
        self._turns: dict[str, tuple[asyncio.Lock, int]] = {}  # UDN → its lock and how many wait for it
        self._plugged = asyncio.Event()
        self._search: asyncio.Task[None] | None = None
        self._changes: asyncio.Queue[CellChange] = asyncio.Queue()
        self._listener = AdvertisementListener(network)
        self._task: asyncio.Task[None] | None = None
        self.lds = lds
        self._lds_task: asyncio.Task[None] | None = None
        self._on_lds: dict[str, str] = {}  # application URI -> URL, of the devices plugged through the LDS
        self._lds_refused: dict[str, str] = {}  # application URI -> URL refused there (not read again)

    @property
    def cell(self) -> Cell:
        """The devices present now, sorted by id."""
        return Cell(self.name, tuple(sorted(self._devices.values(), key=lambda d: d.id)))

    async def __aenter__(self) -> LiveCell:
        await self._listener.start()
        mx = self.search_timeout if self.quiet is None else self.quiet  # answers must come within the quiet period
        search = DeviceSearch(self.network, mx=max(1, min(5, int(mx))))
        try:
            await search.start()
        except BaseException:
            await self._listener.stop()
            raise
        self._news = asyncio.get_running_loop().time()
        if self.lds is not None:  # asked beside the search, as a device is read: a slow LDS holds up nothing
            first = asyncio.create_task(self._asked_lds(self.lds))
            self._readings.add(first)
            first.add_done_callback(self._readings.discard)
            self._lds_task = asyncio.create_task(self._follow_lds(self.lds, first))
        self._search = asyncio.create_task(self._follow_search(search))
        self._task = asyncio.create_task(self._follow())
        try:
            await self._wait_at_start()
        except BaseException:
            await self.__aexit__(None, None, None)
            raise
        return self

    async def _wait_at_start(self) -> None:
        """Until the window ends (and the devices answering in it are read), the expected devices are in, or
        the answers settle."""
        assert self._search is not None
        while not self._search.done() and not self._expected_present() and not self._settled():
            self._plugged.clear()
            news = asyncio.create_task(self._plugged.wait())
            await asyncio.wait((self._search, news), timeout=self._until_settled(),
                               return_when=asyncio.FIRST_COMPLETED)
            news.cancel()
        if self._search.done() and (error := self._search.exception()) is not None:
            raise error

    def _expected_present(self) -> bool:
        """Whether every expected device is in the cell, or as many as expected (never, when none is expected:
        the window decides)."""
        if self.expected_count is not None and len(self._devices) >= self.expected_count:
            return True
        return bool(self.expected) and self.expected <= {d.id for d in self._devices.values()}

    def _settled(self) -> bool:
        """Whether ``quiet`` seconds passed without news and no device is being read."""
        return self._until_settled() == 0.0

    def _until_settled(self) -> float | None:
        if self.quiet is None:
            return None
        if self._readings:
            return self.quiet
        return max(0.0, self.quiet - (asyncio.get_running_loop().time() - self._news))

    def _note_news(self) -> None:
        self._news = asyncio.get_running_loop().time()
        self._plugged.set()

    @property
    def reading(self) -> int:
        """How many devices are being read now."""
        return len(self._readings)

    async def __aexit__(self, *exc_info: object) -> None:
        for task in (self._task, self._search, self._lds_task, *self._readings):
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
        if change.kind == "refused":
            self.refused.pop(change.device, None)  # the latest refusal last
            self.refused[change.device] = RefusedDevice(change.device, change.location, change.reason)
            while len(self.refused) > MAX_REFUSED:  # any number of UDNs may be announced: the oldest go
                del self.refused[next(iter(self.refused))]
        self._changes.put_nowait(change)
        self._note_news()

    async def _follow_search(self, search: DeviceSearch) -> None:
        """Read each device that answers the search as it answers, until the window ends; then wait for those
        readings (each within its budget)."""
        deadline = asyncio.get_running_loop().time() + self.search_timeout
        try:
            while (left := deadline - asyncio.get_running_loop().time()) > 0:
                try:
                    hit = await search.next_hit(left)
                except ProtocolTimeout:
                    break
                self._note_news()
                self._read(hit)
        finally:
            search.stop()
        for hit in search.pending():  # answered in the window, not yet taken
            self._read(hit)
        while self._readings and not self._expected_present():
            await asyncio.wait(set(self._readings))

    async def _follow(self) -> None:
        while True:
            ad = await self._listener.next(None)
            self._note_news()
            if ad.alive:
                self._read(ad)
            elif ad.udn in self._devices:
                self._start(self._unplug_confirmed(ad.udn), ad)

    async def _follow_lds(self, lds: str, first: asyncio.Task[None]) -> None:
        """After the ``first`` question, ask the LDS again and again: plug the devices newly registered, unplug
        those no longer registered."""
        await first
        while True:
            await asyncio.sleep(LDS_POLL)
            await self._asked_lds(lds)

    async def _asked_lds(self, lds: str) -> None:
        """Ask the LDS once. One that fails (away, silent, an answer beyond the limits) is refused, named by its
        URL, once until it answers again; the cell stays as it is and discovery by SSDP goes on."""
        from plugnproduce.discovery.opcua import registered  # asyncua loads only for an LDS

        try:
            servers = await registered(lds, self.device_budget)
        except ProtocolError as exc:
            said = self.refused.get(lds)
            if said is None or said.reason != " ".join(str(exc).split())[:500]:
                self._publish(CellChange("refused", lds, self.cell, str(exc), lds))
            return
        self.refused.pop(lds, None)
        self._ask_lds(servers)

    def _ask_lds(self, servers: list[tuple[str, str]]) -> None:
        listed = {opcua_spec.application_uri_for(device): (device, url) for device, url in servers}
        for uri in [u for u in self._on_lds if u not in listed]:
            self._on_lds.pop(uri)
            gone = self._devices.pop(uri, None)
            if gone is not None:
                self._publish(CellChange("unplug", gone.id, self.cell))
        self._lds_refused = {u: url for u, url in self._lds_refused.items() if listed.get(u, ("", ""))[1] == url}
        for uri, (device, url) in listed.items():
            if uri not in self._on_lds and self._lds_refused.get(uri) != url:
                task = asyncio.create_task(self._plug_registered(uri, device, url))
                self._readings.add(task)
                task.add_done_callback(self._readings.discard)

    async def _plug_registered(self, uri: str, device_id: str, url: str) -> None:
        from plugnproduce.discovery.opcua import read_registered

        async with self._turn(uri):
            if uri in self._on_lds or any(d.id == device_id for d in self._devices.values()):
                return  # plugged meanwhile, or found by SSDP already
            result = await read_registered(device_id, url, self.taxonomy, self.device_budget)
            if isinstance(result, Refusal):
                self._lds_refused[uri] = url
                self._publish(CellChange("refused", uri, self.cell, result.reason, url))
                return
            self._devices[uri], self._on_lds[uri] = result, url
            self.refused.pop(uri, None)
            self._publish(CellChange("plug", result.id, self.cell))

    def _read(self, ad: Advertisement | SearchHit) -> None:
        """Read a device that answered or announced itself, beside the others."""
        self._start(self._plug_advertised(ad), ad)

    def _start(self, work: Coroutine[None, None, None], ad: Advertisement | SearchHit) -> None:
        async def guarded() -> None:
            try:
                await work
            except Exception as exc:  # noqa: BLE001 - one device's defect must never stop following the others
                _LOGGER.warning("device %s: %s: %s", ad.udn, type(exc).__name__, exc)
                self._refuse(ad, f"{type(exc).__name__}: {exc}")

        task = asyncio.create_task(guarded())
        self._readings.add(task)
        task.add_done_callback(self._readings.discard)

    def _refuse(self, ad: Advertisement | SearchHit, reason: str, *, retry: bool = False) -> None:
        """Publish the refusal of the device ``ad`` announced; with ``retry`` its next announcement is read again."""
        if retry:
            self._listener.forget(ad.udn, ad.location, ad.source_host)
        self._publish(CellChange("refused", ad.udn, self.cell, reason, ad.location or ad.source_host))

    async def _unplug_confirmed(self, udn: str) -> None:
        """Unplug on a byebye only if the device's own address confirms it is gone (a byebye may be spoofed)."""
        async with self._turn(udn):
            found = self._found.get(udn)
            if found is None:  # unplugged meanwhile
                return
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
                async with asyncio.timeout(self.device_budget):
                    found = await describe(ad)
                    device = await self._fetch(found)
            except TimeoutError:
                self._refuse(ad, f"device {excerpt(ad.udn)} at {excerpt(ad.location or ad.source_host)} did not "
                                 f"serve its description and chart within {self.device_budget:g} s", retry=True)
                return
            except ProtocolTimeout as exc:
                self._refuse(ad, str(exc), retry=True)
                return
            except (ProtocolError, DescriptionError) as exc:
                self._refuse(ad, str(exc))
                return
            except Exception as exc:  # noqa: BLE001 - whatever a device sends, it costs only that device
                self._refuse(ad, f"its description cannot be read ({type(exc).__name__}: {exc})")
                return
            self._devices[found.udn] = device
            self._found[found.udn] = found
            self.refused.pop(found.udn, None)
            self._publish(CellChange("plug", device.id, self.cell))

    async def _fetch(self, found: FoundDevice) -> DeviceDescription:
        """Fetch the device's own description files and read them as any description."""
        async with await UpnpDeviceClient.from_found(found) as client:
            files = await client.fetch_files()
        return read_served(files, found, self.taxonomy)
