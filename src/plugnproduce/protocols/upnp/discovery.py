"""The controller side of SSDP: search for devices and describe what was found (announcements:
:mod:`plugnproduce.protocols.upnp.advertisements`).

async-upnp-client calls plain functions (a coroutine callback would never be
awaited); those put what arrived into asyncio queues and wake waiters.
Everything found carries ``source_host``, the address the SSDP message came
from: the only host the device is trusted for (see
:mod:`plugnproduce.protocols.upnp.boundary`).

A UDN is predictable, so anyone may answer or announce with a device's UDN. The first
message is not trusted blindly: every distinct place (description URL and source host)
a UDN is announced at is a *candidate*, and the first candidate whose description reads
is the device; the others are refused with their reasons.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Callable, Collection
from dataclasses import dataclass

from async_upnp_client.exceptions import UpnpError
from async_upnp_client.search import SsdpSearchListener
from async_upnp_client.utils import CaseInsensitiveDict

from plugnproduce.errors import ProtocolConnectionError, ProtocolError, ProtocolTimeout, RemoteError, excerpt
from plugnproduce.protocols.upnp.boundary import (
    LOOPBACK,
    ChangeSignal,
    NoRedirectRequester,
    SsdpNetwork,
    TrustedRequester,
    reason,
)
from plugnproduce.protocols.upnp.client import load_device
from plugnproduce.protocols.upnp.spec import SERVICE_TYPE
from plugnproduce.protocols.upnp.ssdp import MAX_CANDIDATES, Advertisement, guard_listener, headers_udn
from plugnproduce.safeio import MAX_BYTES

_LOGGER = logging.getLogger(__name__)

DESCRIBE_TIMEOUT = 5.0
"""Seconds reading a discovered device's description may take, unless the caller gives another bound."""


@dataclass(frozen=True)
class SearchHit:
    """A device that answered an SSDP search: its UDN, description URL and the address it answered from."""

    udn: str
    location: str
    source_host: str


@dataclass(frozen=True)
class FoundDevice:
    """A discovered device whose description was read from the address it was discovered at."""

    udn: str
    location: str
    device_type: str
    friendly_name: str
    source_host: str


@dataclass(frozen=True)
class Refusal:
    """A device that answered but was not accepted, and why (e.g. its description is on another host)."""

    udn: str
    location: str
    source_host: str
    reason: str


@dataclass(frozen=True)
class Discovery:
    """What a search found: the devices accepted and those refused."""

    devices: tuple[FoundDevice, ...]
    refused: tuple[Refusal, ...]


class DeviceSearch:
    """An SSDP search (M-SEARCH) and the answers to it, one per device.

    ``async with DeviceSearch() as search: hit = await search.wait_for(udn, 2.0)``.
    Devices wait a random time up to ``mx`` seconds (minus 0.25 s) before they answer.
    """

    def __init__(self, network: SsdpNetwork = LOOPBACK, search_target: str = SERVICE_TYPE, mx: int = 1) -> None:
        self.network = network
        self.search_target = search_target
        self.mx = mx
        self.hits: dict[str, SearchHit] = {}
        """The first answer of each device, by UDN."""
        self.candidates: dict[str, list[SearchHit]] = {}
        """Every distinct answer (description URL, source host) per UDN, in the order they came."""
        self._queue: asyncio.Queue[SearchHit] = asyncio.Queue()
        self._changed = ChangeSignal()
        self._listener: SsdpSearchListener | None = None

    async def __aenter__(self) -> DeviceSearch:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        self.stop()

    async def start(self) -> None:
        """Open the socket and send the search."""
        listener = SsdpSearchListener(
            callback=self._on_response,
            loop=asyncio.get_running_loop(),
            source=self.network.source,
            target=self.network.target,
            timeout=self.mx,
            search_target=self.search_target,
        )
        try:
            await listener.async_start()
        except (OSError, UpnpError) as exc:
            raise ProtocolConnectionError(
                f"SSDP search on {self.network.interface} for {self.network.group}:{self.network.port}: "
                f"cannot open the socket ({reason(exc)}); multicast must be possible on that interface"
            ) from exc
        guard_listener(listener)
        self._listener = listener
        self.search_again()

    def search_again(self) -> None:
        """Send the M-SEARCH once more (UDP may lose a datagram); answers already seen are not repeated."""
        if self._listener is None:
            raise ProtocolError("the SSDP search is not started")
        self._listener.async_search()

    def stop(self) -> None:
        """Close the socket; later answers are not received."""
        listener, self._listener = self._listener, None
        if listener is not None:
            listener.async_stop()

    def _on_response(self, headers: CaseInsensitiveDict) -> None:
        found = headers_udn(headers)
        if found is None or found[1] is None:
            return
        hit = SearchHit(found[0], found[1], found[2])
        known = self.candidates.setdefault(hit.udn, [])
        if hit in known or len(known) >= MAX_CANDIDATES:
            return
        known.append(hit)
        self.hits.setdefault(hit.udn, hit)
        self._queue.put_nowait(hit)
        self._changed.notify()

    async def next_hit(self, timeout: float) -> SearchHit:
        """The next candidate (a device, or another place answering for a UDN already seen);
        :class:`~plugnproduce.errors.ProtocolTimeout` if none comes in time."""
        try:
            async with asyncio.timeout(timeout):
                return await self._queue.get()
        except TimeoutError as exc:
            raise ProtocolTimeout(f"SSDP search for {self.search_target}: no new answer within {timeout:g} s") from exc

    def pending(self) -> list[SearchHit]:
        """The candidates that answered and were not yet taken by :meth:`next_hit`, now taken."""
        taken = []
        while not self._queue.empty():
            taken.append(self._queue.get_nowait())
        return taken

    async def wait_for(self, udn: str, timeout: float) -> SearchHit:
        """The answer of the device ``udn``, as soon as it arrives."""
        return await self._changed.wait_for(lambda: self.hits.get(udn), timeout, f"SSDP search for {udn}")

    async def wait_until(self, done: Callable[[], bool], timeout: float) -> None:
        """Return once ``done()`` holds (looked at after each answer); ProtocolTimeout after ``timeout`` seconds."""
        await self._changed.wait_for(lambda: True if done() else None, timeout, f"SSDP search for {self.search_target}")


async def describe(found: SearchHit | Advertisement, *, timeout: float = DESCRIBE_TIMEOUT) -> FoundDevice:
    """Read the description of a device seen by SSDP, from the address it was seen at only.

    A description URL on another host than ``found.source_host`` is refused with
    :class:`~plugnproduce.protocols.upnp.boundary.UntrustedUrlError` before any
    connection is made; a description naming another UDN is a
    :class:`~plugnproduce.errors.RemoteError`.
    """
    if found.location is None:
        raise RemoteError(f"device {found.udn} from {found.source_host} gave no description URL")
    what = f"device {excerpt(found.udn)} at {excerpt(found.location)}"  # both as the peer sent them
    requester = TrustedRequester(NoRedirectRequester(timeout, MAX_BYTES), found.source_host, what)
    device = await load_device(found.location, requester, what, timeout)
    if device.udn.lower() != found.udn.lower():
        raise RemoteError(f"{what}: its description names UDN {excerpt(device.udn)}; it was discovered as "
                          f"{excerpt(found.udn)}")
    return FoundDevice(found.udn, found.location, device.device_type, device.friendly_name, found.source_host)


async def _describe_or_refuse(hit: SearchHit, timeout: float) -> FoundDevice | Refusal:
    try:
        return await describe(hit, timeout=timeout)
    except ProtocolError as exc:
        _LOGGER.warning("refused %s: %s", hit.udn, exc)
        return Refusal(hit.udn, hit.location, hit.source_host, str(exc))


async def discover(
    timeout: float = 2.0,
    *,
    network: SsdpNetwork = LOOPBACK,
    search_target: str = SERVICE_TYPE,
    describe_timeout: float = DESCRIBE_TIMEOUT,
    expected: Collection[str] = (),
) -> Discovery:
    """Search for devices for ``timeout`` seconds, then read each one's description.

    SSDP gives no end to the answers, so the whole ``timeout`` is waited, unless the
    UDNs of the ``expected`` devices are given: then each answer's description is read
    as it comes, and the search ends as soon as each expected UDN has one that reads (an
    early answer under its UDN that does not read, a squatter's, does not end the wait).
    Devices answer within ``MX`` seconds, here ``timeout`` rounded
    down and clamped to 1..5, so ``timeout`` should be at least 1 s. By default only
    Plug'n'Produce devices (those with
    :data:`~plugnproduce.protocols.upnp.spec.SERVICE_TYPE`) answer.
    """
    mx = max(1, min(5, int(timeout)))
    wanted = frozenset(expected)
    async with DeviceSearch(network, search_target, mx) as search:
        if wanted:
            results = await _read_until_expected(search, wanted, timeout, describe_timeout)
        else:
            await asyncio.sleep(timeout)  # the search window: answers arrive through the callback meanwhile
    if not wanted:
        hits = [hit for udn in sorted(search.candidates) for hit in search.candidates[udn]]
        results = await asyncio.gather(*(_describe_or_refuse(hit, describe_timeout) for hit in hits))
    devices: dict[str, FoundDevice] = {}
    refused: list[Refusal] = []
    for result in sorted(results, key=lambda r: r.udn):  # per UDN in the order its candidates answered:
        if isinstance(result, Refusal):                   # the first that reads is the device
            refused.append(result)
        elif result.udn in devices:
            refused.append(Refusal(result.udn, result.location, result.source_host,
                                   f"device {result.udn} already answers at {devices[result.udn].location}; this "
                                   f"is another place announcing the same UDN"))
        else:
            devices[result.udn] = result
    return Discovery(tuple(devices.values()), tuple(refused))


async def _read_until_expected(search: DeviceSearch, wanted: frozenset[str], timeout: float,
                               describe_timeout: float) -> list[FoundDevice | Refusal]:
    """Each candidate's description read as it answers, until every ``wanted`` UDN has one that reads or
    ``timeout`` passes; readings under way then end (each within ``describe_timeout``)."""
    readings: dict[SearchHit, asyncio.Task[FoundDevice | Refusal]] = {}
    read: set[str] = set()
    settled = asyncio.Event()

    def note(task: asyncio.Task[FoundDevice | Refusal]) -> None:
        result = None if task.cancelled() or task.exception() else task.result()
        if isinstance(result, FoundDevice):
            read.add(result.udn)
            if wanted <= read:
                settled.set()

    def start_reading(hit: SearchHit) -> None:
        if hit not in readings:
            readings[hit] = asyncio.ensure_future(_describe_or_refuse(hit, describe_timeout))
            readings[hit].add_done_callback(note)

    async def follow() -> None:
        with contextlib.suppress(ProtocolTimeout):
            while True:
                start_reading(await search.next_hit(timeout))

    follower = asyncio.ensure_future(follow())
    try:
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(settled.wait(), timeout)
        follower.cancel()
        for hit in [hit for hits in search.candidates.values() for hit in hits]:  # any not yet taken from the queue
            start_reading(hit)
        return list(await asyncio.gather(*readings.values()))
    finally:  # cancelled: nothing is left reading
        for task in (follower, *readings.values()):
            task.cancel()
