"""Fault injection for the device side: make a device misbehave on purpose, explicitly.

A :class:`Faults` object holds rules; the :class:`~plugnproduce.protocols.xirp.server.XirpServer`
it is given consults it for every request it answers and every event it sends. A
rule names the request or event it applies to (or ``None``: any) and how many
times it fires (``None``: every time). Rules can be added and cleared while the
server runs; each firing is recorded in :attr:`Faults.fired`.

>>> faults = Faults()
>>> _ = faults.add(FaultKind.DROP_RESPONSE, "Open")             # the next Open gets no answer
>>> _ = faults.add(FaultKind.DELAY_EVENT, "gripper_closed", delay=0.2, times=None)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from plugnproduce.protocols.xirp.messages import CODE_PATTERN, FAILED, INVALID_VALUE, STATE, MessageError


class FaultKind(StrEnum):
    """What a fault does. The first four apply to requests, the last four to events."""

    DROP_RESPONSE = "drop-response"
    """The request is handled, but its response is never sent."""
    ERROR_RESPONSE = "error-response"
    """The request is not handled; the response is a failure with the rule's ``code`` and ``text``."""
    MALFORMED_RESPONSE = "malformed-response"
    """The request is handled; instead of its response the rule's ``payload`` is sent (not valid XIRP)."""
    DISCONNECT = "disconnect"
    """The request is not handled; the connection is aborted at once, without ``bye``."""
    DROP_EVENT = "drop-event"
    """The event is counted (its sequence number is used) but sent to nobody."""
    DELAY_EVENT = "delay-event"
    """The event is sent ``delay`` seconds late (events emitted meanwhile overtake it)."""
    DUPLICATE_EVENT = "duplicate-event"
    """The event is sent twice, with the same sequence number."""
    MALFORMED_EVENT = "malformed-event"
    """Instead of the event the rule's ``payload`` is sent (the sequence number is used up)."""


REQUEST_FAULTS = frozenset(
    {FaultKind.DROP_RESPONSE, FaultKind.ERROR_RESPONSE, FaultKind.MALFORMED_RESPONSE, FaultKind.DISCONNECT}
)
EVENT_FAULTS = frozenset(
    {FaultKind.DROP_EVENT, FaultKind.DELAY_EVENT, FaultKind.DUPLICATE_EVENT, FaultKind.MALFORMED_EVENT}
)

MALFORMED_PAYLOAD = b'<response xmlns="urn:plugnproduce-org:xirp:1" id="'
"""Default payload of the malformed faults: a document cut off in the middle."""


@dataclass
class FaultRule:
    """One rule: do ``kind`` to the request or event called ``name`` (``None``: any but the state query
    ``state``, which a rule hits only by its name), ``times`` times."""

    kind: FaultKind
    name: str | None = None
    times: int | None = 1
    """How many more times the rule fires; ``None``: every time."""
    delay: float = 0.0
    """Seconds of delay (``DELAY_EVENT``)."""
    code: str = FAILED
    """Failure code (``ERROR_RESPONSE``)."""
    text: str = "fault injected"
    """Failure text (``ERROR_RESPONSE``)."""
    payload: bytes = MALFORMED_PAYLOAD
    """What is sent in a frame instead of the message (``MALFORMED_RESPONSE``, ``MALFORMED_EVENT``)."""

    def __post_init__(self) -> None:
        self.kind = FaultKind(self.kind)
        if self.times is not None and self.times < 1:
            raise MessageError(f"fault {self.kind}: times={self.times}; expected at least 1, or None", INVALID_VALUE)
        if self.delay < 0 or (self.delay > 0 and self.kind is not FaultKind.DELAY_EVENT):
            raise MessageError(
                f"fault {self.kind}: delay={self.delay}; only delay-event takes a delay, of 0 s or more", INVALID_VALUE
            )
        if not CODE_PATTERN.fullmatch(self.code):
            raise MessageError(f"fault {self.kind}: code {self.code!r} is not an XIRP error code", INVALID_VALUE)

    def matches(self, kinds: frozenset[FaultKind], name: str) -> bool:
        """Whether the rule applies to a message of one of ``kinds`` called ``name``."""
        named = self.name == name if self.name is not None else name != STATE
        return self.kind in kinds and named and self.times != 0


@dataclass
class Faults:
    """The fault rules of one device, consulted in the order they were added (the first match fires)."""

    rules: list[FaultRule] = field(default_factory=list)
    fired: list[tuple[FaultKind, str]] = field(default_factory=list)
    """Each firing so far: the kind and the request or event name it hit."""

    def add(
        self,
        kind: FaultKind | str,
        name: str | None = None,
        *,
        times: int | None = 1,
        delay: float = 0.0,
        code: str = FAILED,
        text: str = "fault injected",
        payload: bytes = MALFORMED_PAYLOAD,
    ) -> FaultRule:
        """Add a rule (see :class:`FaultRule`) and return it."""
        rule = FaultRule(FaultKind(kind), name, times, delay, code, text, payload)
        self.rules.append(rule)
        return rule

    def clear(self) -> None:
        """Remove every rule (the record of firings stays)."""
        self.rules.clear()

    def take(self, kinds: frozenset[FaultKind], name: str) -> FaultRule | None:
        """The first rule of ``kinds`` that applies to ``name``, counted as fired; ``None`` if none applies."""
        for rule in self.rules:
            if rule.matches(kinds, name):
                if rule.times is not None:
                    rule.times -= 1
                    if rule.times == 0:
                        self.rules.remove(rule)
                self.fired.append((rule.kind, name))
                return rule
        return None
