"""A session's state between macrosteps, taken and put back: for exploring more than one future.

A :class:`Snapshot` holds what a later macrostep depends on: the active states, the history,
the values of the datamodel variables the chart assigns, the delayed sends not yet delivered
and the external queue. Its :attr:`~Snapshot.key` is equal for two snapshots that behave alike
(send ids, due times and variables no ``<assign>`` changes are left out), so a search can tell
a configuration it has seen.

Delayed sends are not released by the clock while a session is driven this way: the caller
picks which one arrives next (:func:`fire`); an explorer treats their delays as unknown.
"""

from __future__ import annotations

import copy
import heapq
from collections.abc import Hashable
from dataclasses import dataclass
from typing import Any

from plugnproduce.statechart.model import Assign, walk
from plugnproduce.statechart.runtime.compiled import CState
from plugnproduce.statechart.runtime.dispatch import _Delayed
from plugnproduce.statechart.runtime.events import Event, MacroStep
from plugnproduce.statechart.runtime.interpreter import Interpreter

_NEVER = 1e18
"""Due time given to restored delayed sends: the clock never reaches it, only :func:`fire` delivers them."""
_PLAIN = (int, float, str, bool, type(None), tuple, frozenset)


@dataclass(frozen=True)
class Pending:
    """A delayed send waiting in a session: its send id, event, target and I/O processor type."""

    sendid: str
    event: Event
    target: str | None
    type: str
    named: bool
    """Whether the chart named it (``<send id>``, so a ``<cancel>`` may refer to it)."""

    @property
    def key(self) -> Hashable:
        """What tells this send from another one (an id the session made up left out)."""
        return (self.sendid if self.named else None, self.event.name, _value_key(self.event.data), self.target,
                self.type)


@dataclass(frozen=True)
class Snapshot:
    """A session between macrosteps (see the module's description)."""

    config: frozenset[CState]
    history: tuple[tuple[CState, tuple[CState, ...]], ...]
    data: tuple[Any, ...]
    delayed: tuple[Pending, ...]
    external: tuple[Event, ...]
    running: bool
    final_state: str | None
    key: Hashable

    @property
    def states(self) -> list[str]:
        """Ids of the active states in document order."""
        return [s.id for s in sorted(self.config, key=lambda s: s.idx)]


def assigned_variables(interpreter: Interpreter) -> tuple[str, ...]:
    """The datamodel variables some ``<assign>`` of the chart writes (the others keep their first value)."""
    names = {node.location.split("[")[0].split(".")[0].strip()
             for node in walk(interpreter.chart) if isinstance(node, Assign)}
    return tuple(sorted(names))


def take(interpreter: Interpreter, variables: tuple[str, ...]) -> Snapshot:
    """The session's state now; ``variables``: the datamodel variables it may change."""
    data = tuple(_frozen(interpreter.dm.get(v)) for v in variables)
    made_up = f"send.{interpreter.session_id}."
    delayed = tuple(Pending(d.sendid, d.event, d.target, d.type, not d.sendid.startswith(made_up))
                    for d in sorted(interpreter._delayed, key=lambda d: d.seq) if not d.cancelled)
    history = tuple(sorted(((h, tuple(sorted(v, key=lambda s: s.idx))) for h, v in interpreter._history.items()),
                           key=lambda hv: hv[0].idx))
    external = tuple(interpreter.external)
    config = frozenset(interpreter._config)
    key = (config, tuple((h.idx, tuple(s.idx for s in v)) for h, v in history), tuple(map(_value_key, data)),
           tuple(sorted((p.key for p in delayed), key=repr)), tuple((e.name, _value_key(e.data)) for e in external),
           interpreter.running, interpreter.final_state)
    return Snapshot(config, history, data, delayed, external, interpreter.running, interpreter.final_state, key)


def restore(interpreter: Interpreter, snapshot: Snapshot, variables: tuple[str, ...]) -> None:
    """Put the session back into ``snapshot`` (taken with the same ``variables``)."""
    interpreter._config = set(snapshot.config)
    interpreter._atomic = None
    interpreter._history = {h: list(v) for h, v in snapshot.history}
    for name, value in zip(variables, snapshot.data, strict=True):
        interpreter.dm[name] = value if isinstance(value, _PLAIN) else copy.deepcopy(value)
    interpreter._delayed, interpreter._pending = [], {}
    for i, p in enumerate(snapshot.delayed):
        entry = _Delayed(_NEVER + i, i, p.sendid, p.event, p.target, p.type)
        heapq.heappush(interpreter._delayed, entry)
        interpreter._pending.setdefault(entry.sendid, []).append(entry)
    interpreter.external.clear()
    interpreter.external.extend(snapshot.external)
    interpreter.internal.clear()
    interpreter._to_invoke.clear()
    interpreter.running, interpreter.final_state = snapshot.running, snapshot.final_state


def fire(interpreter: Interpreter, pending: Pending) -> MacroStep | None:
    """Deliver a delayed send now (its delay has passed); the macrostep it causes, if it goes to this session."""
    for entry in interpreter._delayed:
        if not entry.cancelled and entry.event is pending.event:
            entry.cancelled = True
            interpreter._forget(entry)
            break
    problem = interpreter._deliver(pending.event, pending.target, pending.type)
    if problem is not None:
        interpreter._error("error.communication", problem)
    return interpreter.execute_once() if interpreter.external or interpreter.internal else None


def _frozen(value: Any) -> Any:
    return value if isinstance(value, _PLAIN) else copy.deepcopy(value)


def _value_key(value: Any) -> Hashable:
    return value if isinstance(value, int | float | str | bool | type(None)) else repr(value)
