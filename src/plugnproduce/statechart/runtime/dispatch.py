"""Sending events: the SCXML event I/O processor, registered external I/O processors,
delayed sends (against the injected clock) and ``<cancel>``.
"""

from __future__ import annotations

import heapq
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from plugnproduce.statechart.runtime.actions import ActionError
from plugnproduce.statechart.runtime.clock import Clock
from plugnproduce.statechart.runtime.events import (
    EVENT_SENT,
    SCXML_IO,
    SCXML_TYPES,
    Event,
    EventData,
    IOProcessor,
    SentEvent,
)

if TYPE_CHECKING:
    from plugnproduce.statechart.runtime.events import MacroStep, MetaEvent
    from plugnproduce.statechart.runtime.interpreter import Interpreter

_SCXML_PREFIX = "#_scxml_"


@dataclass(order=True)
class _Delayed:
    due: float
    seq: int
    sendid: str = field(compare=False)
    event: Event = field(compare=False)
    target: str | None = field(compare=False)
    type: str = field(compare=False)
    cancelled: bool = field(default=False, compare=False)


class DispatchSession(Protocol):
    """What the dispatcher needs of its session: its own state, and the errors, meta events and invoked
    sessions the other parts keep."""

    session_id: str
    clock: Clock
    io_processors: dict[str, IOProcessor]
    internal: deque[Event]
    external: deque[Event]
    invokeid: str | None
    _parent: Interpreter | None
    _sessions: dict[str, Interpreter]
    _step: MacroStep | None
    _observers: list[Callable[[MetaEvent], None]]
    _delayed: list[_Delayed]
    _pending: dict[str, list[_Delayed]]
    delay_policy: Callable[[float], float] | None

    def _error(self, name: str, message: str, sendid: str | None = None) -> None: ...

    def _notify(self, name: str, **data: Any) -> None: ...

    def _children(self) -> list[Interpreter]: ...

    def _child(self, invokeid: str) -> Interpreter | None: ...

    def _deliver(self: DispatchSession, event: Event, target: str | None, kind: str) -> str | None: ...

    def _forget(self, entry: _Delayed) -> None: ...

    def _next_seq(self) -> int: ...


class Dispatcher:
    """The sending half of a session (mixed into the interpreter)."""

    session_id: str
    clock: Clock
    io_processors: dict[str, IOProcessor]
    internal: deque[Event]
    external: deque[Event]
    invokeid: str | None
    _parent: Interpreter | None
    _sessions: dict[str, Interpreter]
    _step: MacroStep | None
    _observers: list[Callable[[MetaEvent], None]]

    def _init_dispatch(self) -> None:
        self.delay_policy: Callable[[float], float] | None = None
        """Maps a delayed send's delay (seconds, as the chart says) to the one it takes (a simulated device
        scaled by a speed factor, or timed by its declared durations); None: as the chart says."""
        self._delayed: list[_Delayed] = []
        self._pending: dict[str, list[_Delayed]] = {}
        self._counter = 0

    def new_sendid(self) -> str:
        """A fresh send id for a ``<send>`` without ``id``."""
        self._counter += 1
        return f"send.{self.session_id}.{self._counter}"

    def io_locations(self) -> dict[str, dict[str, Any]]:
        """The ``_ioprocessors`` system variable: type → {"location": ...}."""
        scxml = EventData(location=_SCXML_PREFIX + self.session_id)
        out: dict[str, dict[str, Any]] = {SCXML_IO: scxml, "scxml": scxml}
        for kind, processor in self.io_processors.items():
            out[kind] = EventData(location=getattr(processor, "location", None))
        return out

    def send(self: DispatchSession, name: str, target: str | None, kind: str | None, delay: float, data: Any,
             sendid: str, visible_sendid: str | None) -> None:
        """Execute a ``<send>``: check it, record it, then deliver it now or after ``delay`` seconds."""
        kind = str(kind) if kind is not None else SCXML_IO
        target = str(target) if target is not None else None
        if delay > 0 and self.delay_policy is not None:
            delay = self.delay_policy(delay)
        if kind in SCXML_TYPES:
            if target is not None and not target.startswith("#_"):
                raise ActionError(f"send target {target!r} is not supported by the SCXML processor; expected "
                                  "#_internal, #_parent, #_scxml_SESSION or #_INVOKEID", sendid=sendid)
        elif kind not in self.io_processors:
            raise ActionError(f"send type {kind!r} has no I/O processor; expected one of "
                              f"{sorted(self.io_processors) + ['scxml']}", sendid=sendid)
        event = Event(name, data, "external", visible_sendid, _SCXML_PREFIX + self.session_id,
                      SCXML_IO if kind in SCXML_TYPES else kind)
        sent = SentEvent(event, target, kind, delay)
        if self._step is not None:
            self._step.sent.append(sent)
        if self._observers:
            self._notify(EVENT_SENT, sent=sent)
        if delay > 0:
            entry = _Delayed(self.clock.time() + delay, self._next_seq(), sendid, event, target, kind)
            heapq.heappush(self._delayed, entry)
            self._pending.setdefault(sendid, []).append(entry)
            return
        problem = self._deliver(event, target, kind)
        if problem is not None:
            raise ActionError(problem, "error.communication", sendid)

    def cancel(self, sendid: str) -> None:
        """Cancel a delayed send of this session (nothing happens if it has gone or never was)."""
        for entry in self._pending.pop(sendid, ()):
            entry.cancelled = True

    def next_due(self: DispatchSession) -> float | None:
        """Clock time of the next delayed send of this session or its invoked sessions (None: none)."""
        while self._delayed and self._delayed[0].cancelled:
            heapq.heappop(self._delayed)
        times = [self._delayed[0].due] if self._delayed else []
        for child in self._children():
            due = child.next_due()
            if due is not None:
                times.append(due)
        return min(times) if times else None

    def _release_due(self: DispatchSession) -> None:
        """Deliver every delayed send whose time has come, in due order."""
        if not self._delayed:
            return
        now = self.clock.time()
        while self._delayed and self._delayed[0].due <= now:
            entry = heapq.heappop(self._delayed)
            if entry.cancelled:
                continue
            self._forget(entry)
            problem = self._deliver(entry.event, entry.target, entry.type)
            if problem is not None:
                self._error("error.communication", problem, entry.sendid)

    def _deliver(self: DispatchSession, event: Event, target: str | None, kind: str) -> str | None:
        """Hand the event over; the problem as text when it cannot be delivered."""
        if kind not in SCXML_TYPES:
            try:
                self.io_processors[kind].send(event, target, kind)
            except Exception as exc:  # any failure of a device protocol is error.communication in the chart
                return f"I/O processor {kind!r} failed to send {event.name!r}: {exc}"
            return None
        if target is None:
            self.external.append(event)
        elif target == "#_internal":
            event.type = "internal"
            self.internal.append(event)
        elif target == "#_parent":
            if self._parent is None:
                return "send target #_parent: this session was not invoked"
            self._parent._from_child(self.invokeid, event)
        elif target.startswith(_SCXML_PREFIX):
            session = self._sessions.get(target[len(_SCXML_PREFIX):])
            if session is None or not session.running:
                return f"send target {target!r}: no such session"
            session.external.append(event)
        else:
            child = self._child(target[2:])
            if child is None:
                return f"send target {target!r}: no such invoked session"
            child.external.append(event)
        return None

    def _forget(self, entry: _Delayed) -> None:
        entries = self._pending.get(entry.sendid, [])
        if entry in entries:
            entries.remove(entry)
        if not entries:
            self._pending.pop(entry.sendid, None)

    def _next_seq(self) -> int:
        self._counter += 1
        return self._counter
