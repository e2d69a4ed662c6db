"""The cell as discovery sees it, as a :class:`~plugnproduce.controller.interfaces.CellSource`.

Every :class:`~plugnproduce.discovery.CellChange` of a :class:`~plugnproduce.discovery.LiveCell`
(an SSDP ``alive`` or ``byebye``, or a device refused) becomes a
:class:`~plugnproduce.controller.interfaces.CellUpdate` for the listeners, in the order discovery saw them.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import threading
from collections.abc import Callable

from plugnproduce import service
from plugnproduce.controller.interfaces import CellListener, CellUpdate
from plugnproduce.description.model import Cell
from plugnproduce.discovery import LiveCell
from plugnproduce.knowledge import Knowledge
from plugnproduce.protocols.opcua.spec import chosen_lds
from plugnproduce.protocols.upnp import SsdpNetwork, network_from_env

log = logging.getLogger(__name__)


class LiveCellSource:
    """The devices discovery finds on ``network`` (default: the one ``PNP_SSDP_PORT`` names); they plug in and
    unplug themselves."""

    def __init__(self, network: SsdpNetwork | None = None, name: str = "live", search_timeout: float = 1.0,
                 knowledge: Knowledge | None = None, serve_lds: int | None = None,
                 announce: Callable[[str], None] | None = None) -> None:
        """``serve_lds``: run a Local Discovery Server on the network's address at this port (0: a free one) for
        the OPC UA devices to register with, its endpoint told to ``announce`` once it listens (else the one
        ``PNP_LDS`` names is asked, if any)."""
        self.network = network if network is not None else network_from_env()
        self._serve_lds, self._announce = serve_lds, announce
        self._live = LiveCell((knowledge or service.knowledge()).taxonomy, network=self.network, name=name,
                              search_timeout=search_timeout, lds=chosen_lds())
        self._cell = Cell(name, ())
        self._listeners: list[CellListener] = []
        self._lock = threading.Lock()
        self._changed = asyncio.Condition()
        self._stack = contextlib.AsyncExitStack()
        self._follower: asyncio.Task[None] | None = None

    @property
    def cell(self) -> Cell:
        """The cell as the listeners were last told it."""
        return self._cell

    def subscribe(self, listener: CellListener) -> Callable[[], None]:
        """Call ``listener`` on every change; the returned function unsubscribes."""
        with self._lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    def refused(self) -> list[dict[str, str]]:
        """The devices discovery refused and has not plugged since: UDN, URL and reason."""
        return [{"udn": r.udn, "url": r.location, "reason": r.reason}
                for r in sorted(self._live.refused.values(), key=lambda r: r.udn)]

    async def start(self) -> None:
        """Start following SSDP announcements (and the LDS)."""
        if self._serve_lds is not None:
            from plugnproduce.controller.devices import serve_lds_on

            self._live.lds = await serve_lds_on(self._stack, self.network.interface, self._serve_lds)
            if self._announce is not None:
                self._announce(self._live.lds)
        await self._stack.enter_async_context(self._live)
        self._follower = asyncio.create_task(self._follow(), name="follow the live cell")

    async def stop(self) -> None:
        """Stop following the cell."""
        if self._follower is not None:
            self._follower.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._follower
        await self._stack.aclose()

    async def wait_until(self, done: Callable[[Cell], bool], timeout: float) -> bool:
        """Wait until ``done(cell)`` holds for the cell as the listeners know it; False after ``timeout`` seconds."""
        async with self._changed:
            try:
                await asyncio.wait_for(self._changed.wait_for(lambda: done(self._cell)), timeout)
            except TimeoutError:
                return False
        return True

    async def _follow(self) -> None:
        async for change in self._live.changes():
            self._cell = change.cell
            self._notify(CellUpdate(change.kind, change.device, change.cell, change.reason,
                                    location=change.location))
            async with self._changed:
                self._changed.notify_all()

    def _notify(self, update: CellUpdate) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            try:
                listener(update)
            except Exception:  # one broken listener must not stop the others hearing of the cell
                log.exception("cell listener %r failed on %s %s", listener, update.kind, update.device)
