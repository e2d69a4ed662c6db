"""Events from one device as a controller receives them: in order, duplicates dropped, bounded.

:class:`EventInbox` sits between the connection (which :meth:`~EventInbox.put`s
each event as it arrives) and whoever reads the events (a callback, or coroutines
awaiting :meth:`~EventInbox.get`). A device numbers its events from 1; an event
whose number was seen before is a duplicate and is dropped.
"""

from __future__ import annotations

import asyncio
import logging
import time
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

KEPT_ERRORS = 64
"""How many of a device's unsolicited protocol errors are kept (the newest; all are counted)."""


class PeerLog:
    """Log lines about one misbehaving peer, at most ``burst`` per ``period`` seconds.

    A device that floods bad frames must not flood the log: past the burst its lines
    are counted, and the count is logged with the next line the period lets through.
    """

    def __init__(self, logger: logging.Logger, burst: int = 5, period: float = 10.0) -> None:
        self._logger, self._burst, self._period = logger, burst, period
        self._window_start = -period
        self._in_window = 0
        self.suppressed = 0
        """Lines not logged since the last one that was."""

    def log(self, level: int, message: str, *args: object) -> None:
        """Log ``message % args`` at ``level`` unless this peer has used up its burst."""
        now = time.monotonic()
        if now - self._window_start >= self._period:
            self._window_start, self._in_window = now, 0
        if self._in_window >= self._burst:
            self.suppressed += 1
            return
        self._in_window += 1
        if self.suppressed:
            message += f" ({self.suppressed} similar line(s) suppressed)"
            self.suppressed = 0
        self._logger.log(level, message, *args)


@dataclass
class LinkStats:
    """What went wrong on a connection without failing a request."""

    malformed: int = 0
    """Frames from the device that were not valid XIRP (each answered with an ``error``)."""
    duplicates: int = 0
    """Events dropped because their sequence number was seen before."""
    overflowed: int = 0
    """Events dropped because the event buffer was full (oldest first)."""
    errors: deque[ErrorMessage] = field(default_factory=lambda: deque(maxlen=KEPT_ERRORS))
    """The newest protocol errors the device reported that named no waiting request."""
    reported: int = 0
    """How many such errors the device reported in all."""
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
        self.log = PeerLog(_LOGGER)
        """The rate-limited log for this connection's peer."""

    def put(self, event: Event) -> None:
        """Take one event from the connection."""
        if event.seq in self._seen:
            self._stats.duplicates += 1
            self.log.log(logging.INFO, "%s: event %s #%d received twice; dropped", self.what, event.name, event.seq)
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
            self.log.log(logging.WARNING, "%s: event buffer full; the oldest event is dropped", self.what)
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
