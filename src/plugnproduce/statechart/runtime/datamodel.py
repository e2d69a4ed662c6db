"""The session's datamodel and the running of executable content (mixed into the interpreter).

System variables (``_sessionid``, ``_name``, ``_ioprocessors``, ``_event``, ``In``) are set
before any ``<data>``; with early binding (the default) every ``<data>`` of the document
is initialised at start, with late binding each state's when it is first entered. Values
passed by ``<invoke>`` override ``<data>`` of the same id at the top level. A block of
executable content stops at its first error, which becomes ``error.execution`` (or
``error.communication`` for a send that cannot be delivered) on the internal queue.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from plugnproduce.statechart.runtime.actions import ActionError, Block, literal, markup_value, run_actions
from plugnproduce.statechart.runtime.evaluator import EvaluationError
from plugnproduce.statechart.runtime.events import ERROR, LOG, Event, MetaEvent
from plugnproduce.statechart.runtime.invoke import resolve_src, value_from_file

if TYPE_CHECKING:
    from plugnproduce.statechart.model import Chart, Data
    from plugnproduce.statechart.runtime.compiled import CompiledChart, CState
    from plugnproduce.statechart.runtime.session import DatamodelSession, ErrorSession

log = logging.getLogger("plugnproduce.statechart")


class Datamodel:
    """Variables, executable content, errors, logs and meta events of a session."""

    chart: Chart
    compiled: CompiledChart
    session_id: str
    base_dir: Path | None
    trusted: bool
    dm: dict[str, Any]
    internal: deque[Event]
    _overrides: dict[str, Any]
    _data_ready: set[CState]
    _late: bool
    _observers: list[Callable[[MetaEvent], None]]

    def _init_datamodel(self: DatamodelSession) -> None:
        self.dm.clear()
        self.dm["__builtins__"] = self.compiled.evaluator.builtins()
        self.dm.update(_sessionid=self.session_id, _name=self.chart.name, _ioprocessors=self.io_locations(),
                       _event=None, In=self.is_active)
        if self._late:
            self._bind(self.compiled.root)
            return
        for state in self.compiled.states:
            self._bind(state)

    def _bind(self, state: CState) -> None:
        """Initialise the ``<data>`` of one state (the root's get the values ``<invoke>`` passed)."""
        self._data_ready.add(state)
        top = state is self.compiled.root
        for data in state.data:
            if top and data.id in self._overrides:
                self.dm[data.id] = self._overrides[data.id]
                continue
            try:
                self.dm[data.id] = self._data_value(data)
            except (EvaluationError, ActionError) as exc:
                self.dm[data.id] = None
                self._error("error.execution", f"data {data.id!r}: {exc}")

    def _data_value(self, data: Data) -> Any:
        if data.expr is not None:
            return self.compiled.evaluator.expr(data.expr).evaluate(self.dm)
        if data.src is not None:
            return value_from_file(resolve_src(data.src, self.base_dir, self.trusted))
        if data.markup is not None:
            return markup_value(data.markup)
        if data.text is not None:
            return literal(data.text)
        return None

    def _run(self: ErrorSession, block: Block) -> None:
        """Run a block of executable content; its first error stops it and is raised as an error event."""
        try:
            run_actions(self, block)
        except ActionError as exc:
            self._error(exc.kind, exc.message, exc.sendid)
        except EvaluationError as exc:
            self._error("error.execution", str(exc))

    def _error(self, name: str, message: str, sendid: str | None = None) -> None:
        """Put a platform error event on the internal queue (and tell the observers)."""
        event = Event(name, {"message": message}, "platform", sendid)
        self.internal.append(event)
        log.info("%s: %s: %s", self.chart.name or "chart", name, message)
        if self._observers:
            self._notify(ERROR, event=event)

    def _notify(self, name: str, **data: Any) -> None:
        meta = MetaEvent(name, data)
        for observer in list(self._observers):
            observer(meta)

    def raise_internal(self, name: str) -> None:
        """``<raise>``: an internal event."""
        self.internal.append(Event(name, None, "internal"))

    def log(self, label: str | None, value: Any) -> None:
        """``<log>``: to the logger and the observers."""
        log.info("%s: %s%s", self.chart.name or "chart", f"{label}: " if label else "", value)
        if self._observers:
            self._notify(LOG, label=label, value=value)
