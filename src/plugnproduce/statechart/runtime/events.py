"""Events, and the records the interpreter hands out: macrosteps, sends, meta events."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

SCXML_IO = "http://www.w3.org/TR/scxml/#SCXMLEventProcessor"
"""The SCXML event I/O processor's type URI."""

SCXML_TYPES = frozenset({SCXML_IO, "scxml", "http://www.w3.org/TR/scxml/", "http://www.w3.org/TR/scxml"})
"""Values of ``<send type>`` and ``<invoke type>`` that mean SCXML itself."""


class EventData(dict[str, Any]):
    """Event data built from ``namelist`` and ``<param>``: a dict whose keys also read as attributes."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


@dataclass(slots=True)
class Event:
    """An SCXML event (``_event`` in the datamodel).

    ``type`` is ``external``, ``internal`` or ``platform``; ``origin``/``origintype`` say
    where to send a reply; ``invokeid`` is set on events from an invoked session.
    """

    name: str
    data: Any = None
    type: str = "external"
    sendid: str | None = None
    origin: str | None = None
    origintype: str | None = None
    invokeid: str | None = None


class IOProcessor(Protocol):
    """An event I/O processor for a ``<send type>`` other than SCXML (e.g. ``xirp``, ``upnp``).

    ``send`` is called synchronously when the send is due; it should hand the event
    over (e.g. put it on an asyncio queue) rather than block. An exception it raises
    becomes ``error.communication`` in the chart.
    """

    def send(self, event: Event, target: str | None, type: str) -> None:  # noqa: A002 - the SCXML name
        """Deliver ``event`` to ``target`` over the protocol ``type``."""


@dataclass(frozen=True, slots=True)
class TakenTransition:
    """A transition taken in a microstep: its source state, targets (may be empty) and event descriptors."""

    source: str
    targets: tuple[str, ...]
    event: str | None


@dataclass(frozen=True, slots=True)
class SentEvent:
    """A ``<send>`` executed in a macrostep: the event, where it goes, and its delay in seconds."""

    event: Event
    target: str | None
    type: str
    delay: float


@dataclass(slots=True)
class MacroStep:
    """What one macrostep did: the external event (None for the initial step), the events consumed
    (the external one and any internal ones), the transitions taken, the states exited and
    entered (ids, in order) and the sends executed."""

    time: float
    event: Event | None
    consumed: list[Event] = field(default_factory=list)
    transitions: list[TakenTransition] = field(default_factory=list)
    exited: list[str] = field(default_factory=list)
    entered: list[str] = field(default_factory=list)
    sent: list[SentEvent] = field(default_factory=list)


STATE_ENTERED = "state entered"
STATE_EXITED = "state exited"
EVENT_CONSUMED = "event consumed"
EVENT_SENT = "event sent"
TRANSITION_TAKEN = "transition taken"
LOG = "log"
ERROR = "error"


@dataclass(frozen=True, slots=True)
class MetaEvent:
    """What an observer receives: ``name`` (one of the constants above) and details.

    ``state entered``/``state exited``: ``state``; ``event consumed``: ``event``;
    ``event sent``: ``sent`` (a :class:`SentEvent`); ``transition taken``: ``transition``;
    ``log``: ``label`` and ``value``; ``error``: ``event`` (the error event raised).
    """

    name: str
    data: dict[str, Any]
