"""The controller's ear for SSDP announcements: ``ssdp:alive`` and ``ssdp:byebye``, one report per change.

async-upnp-client calls plain functions (a coroutine callback would never be awaited); those put what
arrived into a queue and wake waiters.
"""

from __future__ import annotations

import asyncio

from async_upnp_client.advertisement import SsdpAdvertisementListener
from async_upnp_client.exceptions import UpnpError
from async_upnp_client.utils import CaseInsensitiveDict

from plugnproduce.errors import ProtocolConnectionError, ProtocolTimeout
from plugnproduce.protocols.upnp.boundary import LOOPBACK, ChangeSignal, SsdpNetwork, reason
from plugnproduce.protocols.upnp.ssdp import MAX_CANDIDATES, Advertisement, guard_listener, headers_udn


class AdvertisementListener:
    """Listen for SSDP ``alive`` and ``byebye`` announcements, one report per change of a device's presence.

    A device sends several announcements (one per device and service type); only
    the first that changes what is known of the device is reported: a device is
    reported alive once per place it is announced at (description URL and source
    host: another place for the same UDN may be the real device where the first
    was an impostor), and gone once. Reports go to a queue (:meth:`next`) and to
    :attr:`seen`, which :meth:`wait_for` looks at.
    """

    def __init__(self, network: SsdpNetwork = LOOPBACK) -> None:
        self.network = network
        self.seen: list[Advertisement] = []
        """Every report so far, oldest first."""
        self._places: dict[str, list[tuple[str | None, str]]] = {}  # UDN → places announced alive; [] once gone
        self._queue: asyncio.Queue[Advertisement] = asyncio.Queue()
        self._changed = ChangeSignal()
        self._listener: SsdpAdvertisementListener | None = None

    async def __aenter__(self) -> AdvertisementListener:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.stop()

    async def start(self) -> None:
        """Open the socket on the SSDP port and join the multicast group."""
        listener = SsdpAdvertisementListener(
            on_alive=self._on_alive,
            on_byebye=self._on_byebye,
            source=self.network.source,
            target=self.network.target,
            loop=asyncio.get_running_loop(),
        )
        try:
            await listener.async_start()
        except (OSError, UpnpError) as exc:
            raise ProtocolConnectionError(
                f"SSDP listener on {self.network.interface} for {self.network.group}:{self.network.port}: "
                f"cannot open the socket ({reason(exc)}); multicast must be possible on that interface"
            ) from exc
        guard_listener(listener)
        self._listener = listener

    async def stop(self) -> None:
        """Close the socket."""
        listener, self._listener = self._listener, None
        if listener is not None:
            await listener.async_stop()

    def _on_alive(self, headers: CaseInsensitiveDict) -> None:
        self._report(headers, alive=True)

    def _on_byebye(self, headers: CaseInsensitiveDict) -> None:
        self._report(headers, alive=False)

    def _report(self, headers: CaseInsensitiveDict, alive: bool) -> None:
        found = headers_udn(headers)
        if found is None:
            return
        places = self._places.get(found[0])
        if alive:
            if places is not None and (found[1], found[2]) in places:
                return
            self._places[found[0]] = [*(places or [])[-(MAX_CANDIDATES - 1):], (found[1], found[2])]
        else:
            if places == []:
                return
            self._places[found[0]] = []
        advertisement = Advertisement(found[0], alive, found[1], found[2])
        self.seen.append(advertisement)
        self._queue.put_nowait(advertisement)
        self._changed.notify()

    def forget(self, udn: str, location: str | None, source_host: str) -> None:
        """Report the next ``alive`` of ``udn`` at this place again (its device is to be tried once more)."""
        places = self._places.get(udn)
        if places and (location, source_host) in places:
            places.remove((location, source_host))

    async def next(self, timeout: float | None) -> Advertisement:
        """The next report; :class:`~plugnproduce.errors.ProtocolTimeout` if none comes in time (None: no limit)."""
        try:
            async with asyncio.timeout(timeout):
                return await self._queue.get()
        except TimeoutError as exc:
            raise ProtocolTimeout(f"SSDP advertisements: none within {timeout:g} s") from exc

    async def wait_for(self, udn: str, alive: bool, timeout: float) -> Advertisement:
        """The report that device ``udn`` is alive (or gone), as soon as it has been seen."""

        def probe() -> Advertisement | None:
            return next((a for a in reversed(self.seen) if a.udn == udn and a.alive is alive), None)

        state = "alive" if alive else "byebye"
        return await self._changed.wait_for(probe, timeout, f"SSDP {state} of {udn}")
