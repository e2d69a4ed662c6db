"""Events from one device as a controller receives them: in order, duplicates dropped, bounded.

:class:`EventInbox` sits between the connection (which :meth:`~EventInbox.put`s
each event as it arrives) and whoever reads the events (a callback, or coroutines
awaiting :meth:`~EventInbox.get`). A device numbers its events from 1; an event
whose number was seen before is a duplicate and is dropped.
"""

from __future__ import annotations

import asyncio
import logging
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from plugnproduce.errors import ProtocolConnectionError
from plugnproduce.protocols.xirp.messages import ErrorMessage, Event

_LOGGER = logging.getLogger(__name__)

EventCallback = Callable[[Event], None]
"""``on_event(event)``: a plain function, called on the event loop for each event as it arrives."""

SEEN_WINDOW = 4096
"""How many recent sequence numbers are remembered to recognise duplicates."""


@dataclass
class LinkStats:
    """What went wrong on a connection without failing a request."""

    malformed: int = 0
    """Frames from the device that were not valid XIRP (each answered with an ``error``)."""
    duplicates: int = 0
    """Events dropped because their sequence number was seen before."""
    overflowed: int = 0
    """Events dropped because the event buffer was full (oldest first)."""
    errors: list[ErrorMessage] = field(default_factory=list)
    """Protocol errors the device reported that named no waiting request."""
    on_anomaly: Callable[[str], None] | None = field(default=None, repr=False, compare=False)
    """Told, in a sentence, about each of the above as it happens (e.g. so an executor can stop)."""

    def tell(self, what: str) -> None:
        """Pass an anomaly on to :attr:`on_anomaly`, if anyone listens."""
        if self.on_anomaly is not None:
            self.on_anomaly(what)


class EventInbox:
    """The events of one connection: to ``on_event`` if given, else into a buffer of ``size`` events."""

    def __init__(self, what: str, on_event: EventCallback | None, size: int, stats: LinkStats) -> None:
        self.what = what
        """Who the events come from, for messages."""
        self._on_event = on_event
        self._buffer: deque[Event] = deque(maxlen=size)
        self._ready = asyncio.Event()
        self._seen: set[int] = set()
        self._seen_order: deque[int] = deque()
        self._stats = stats
        self._ended: str | None = None

    def put(self, event: Event) -> None:
        """Take one event from the connection."""
        if event.seq in self._seen:
            self._stats.duplicates += 1
            _LOGGER.info("%s: event %s #%d received twice; dropped", self.what, event.name, event.seq)
            self._stats.tell(f"{self.what} sent event {event.name} #{event.seq} twice")
            return
        self._seen.add(event.seq)
        self._seen_order.append(event.seq)
        if len(self._seen_order) > SEEN_WINDOW:
            self._seen.discard(self._seen_order.popleft())
        if self._on_event is not None:
            try:
                self._on_event(event)
            except Exception:  # the callback's bug must not stop the connection
                _LOGGER.exception("%s: the event callback raised on %s", self.what, event.name)
            return
        if len(self._buffer) == self._buffer.maxlen:
            self._stats.overflowed += 1
            _LOGGER.warning("%s: event buffer full; the oldest event is dropped", self.what)
        self._buffer.append(event)
        self._ready.set()

    def end(self, why: str) -> None:
        """No more events will come; once the buffer is empty, :meth:`get` raises with ``why``."""
        self._ended = why
        self._ready.set()

    async def get(self) -> Event:
        """The next event, waiting for it; ProtocolConnectionError once ended and empty."""
        while not self._buffer:
            if self._ended is not None:
                raise ProtocolConnectionError(f"events from {self.what}: {self._ended}")
            self._ready.clear()
            await self._ready.wait()
        return self._buffer.popleft()
