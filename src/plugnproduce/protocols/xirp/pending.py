"""The requests a :class:`~plugnproduce.protocols.xirp.client.XirpClient` waits on, with their deadlines.

A response completes the request waiting for it (matched by id); a request past its
deadline fails with :class:`~plugnproduce.errors.ProtocolTimeout`; when the
connection ends, every waiting request fails at once.

One timer serves all waiting requests, set for the earliest deadline, rather than a
timer per request: scheduling and cancelling a timer per request costs more than the
rest of a round trip's bookkeeping together.
"""

from __future__ import annotations

import asyncio
import math
from typing import NamedTuple

from plugnproduce.errors import ProtocolTimeout
from plugnproduce.protocols.xirp.messages import Response

_SLACK = 0.001  # seconds: a request whose deadline is this close when the watchdog fires counts as overdue


class Waiting(NamedTuple):
    """A request waiting for its response."""

    future: asyncio.Future[Response]
    name: str
    limit: float
    deadline: float


class PendingRequests:
    """The waiting requests of one connection, by id, and the one watchdog timer over their deadlines."""

    def __init__(self, what: str) -> None:
        self.what = what
        """The device in messages (it changes once the device's hello names it)."""
        self._waiting: dict[str, Waiting] = {}
        self._watchdog: asyncio.TimerHandle | None = None
        self._watchdog_at = math.inf
        self._next_id = 0

    def next_id(self) -> str:
        """A fresh request id."""
        self._next_id += 1
        return str(self._next_id)

    def wait(self, request_id: str, name: str, limit: float) -> asyncio.Future[Response]:
        """Wait for the response to ``request_id`` for at most ``limit`` seconds: its future."""
        loop = asyncio.get_running_loop()
        future: asyncio.Future[Response] = loop.create_future()
        deadline = loop.time() + limit
        self._waiting[request_id] = Waiting(future, name, limit, deadline)
        if deadline < self._watchdog_at:
            self._arm_watchdog(loop, deadline)
        return future

    def done(self, request_id: str) -> None:
        """Stop waiting for ``request_id`` (answered, failed or given up)."""
        del self._waiting[request_id]

    def get(self, request_id: str) -> Waiting | None:
        """The request ``request_id`` if it is still waiting."""
        return self._waiting.get(request_id)

    def fail_all(self, error: BaseException) -> None:
        """Fail every waiting request with ``error`` and stop the watchdog (the connection ended)."""
        for waiting in self._waiting.values():
            if not waiting.future.done():
                waiting.future.set_exception(error)
        if self._watchdog is not None:
            self._watchdog.cancel()
            self._watchdog, self._watchdog_at = None, math.inf

    def _arm_watchdog(self, loop: asyncio.AbstractEventLoop, deadline: float) -> None:
        if self._watchdog is not None:
            self._watchdog.cancel()
        self._watchdog = loop.call_at(deadline, self._expire_overdue)
        self._watchdog_at = deadline

    def _expire_overdue(self) -> None:
        """Fail every request past its deadline with ProtocolTimeout; set the timer for the next deadline."""
        self._watchdog, self._watchdog_at = None, math.inf
        loop = asyncio.get_running_loop()
        now = loop.time() + _SLACK
        upcoming = math.inf
        for waiting in self._waiting.values():
            if waiting.future.done():
                continue
            if waiting.deadline <= now:
                message = f"request {waiting.name} to {self.what}: no response within {waiting.limit:g} s"
                waiting.future.set_exception(ProtocolTimeout(message))
            else:
                upcoming = min(upcoming, waiting.deadline)
        if upcoming < math.inf:
            self._arm_watchdog(loop, upcoming)
