"""The session as its parts see it: the Protocols through which executable content and the
interpreter's parts (datamodel, invoker, microstep) reach what another part provides.

A part's method that needs another part names its ``self`` with one of these Protocols; the
type checker then holds :class:`~plugnproduce.statechart.runtime.interpreter.Interpreter`, where
the parts come together, to every member each Protocol lists.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from plugnproduce.statechart.model import Chart, Data
    from plugnproduce.statechart.runtime.actions import Block, CInvoke
    from plugnproduce.statechart.runtime.compiled import CompiledChart, CState, CTransition
    from plugnproduce.statechart.runtime.entry import History
    from plugnproduce.statechart.runtime.evaluator import Expr
    from plugnproduce.statechart.runtime.events import Event, MacroStep, MetaEvent
    from plugnproduce.statechart.runtime.interpreter import Interpreter
    from plugnproduce.statechart.runtime.invoke import Invocation

EntrySet = tuple[list["CState"], set["CState"], dict["CState", "Block"]]
"""What a microstep enters: the states in entry order, those entered by default, history defaults' content."""


class ActionSession(Protocol):
    """What executable content needs of the session that runs it."""

    dm: dict[str, Any]

    def holds(self, cond: Expr) -> bool:
        """A condition's truth (false, with ``error.execution``, when it cannot be evaluated)."""
        ...

    def raise_internal(self, name: str) -> None:
        """``<raise>``."""
        ...

    def log(self, label: str | None, value: Any) -> None:
        """``<log>``."""
        ...

    def new_sendid(self) -> str:
        """A fresh send id."""
        ...

    def send(self, name: str, target: str | None, kind: str | None, delay: float, data: Any, sendid: str,
             visible_sendid: str | None) -> None:
        """``<send>``."""
        ...

    def cancel(self, sendid: str) -> None:
        """``<cancel>``."""
        ...


class ErrorSession(ActionSession, Protocol):
    """A session that runs blocks of executable content and raises platform errors."""

    def _run(self, block: Block) -> None: ...

    def _error(self, name: str, message: str, sendid: str | None = None) -> None: ...


class DatamodelSession(ErrorSession, Protocol):
    """What the datamodel needs of its session."""

    chart: Chart
    compiled: CompiledChart
    session_id: str
    _late: bool

    def io_locations(self) -> dict[str, dict[str, Any]]: ...

    def is_active(self, state_id: str) -> bool: ...

    def _bind(self, state: CState) -> None: ...

    def _data_value(self, data: Data) -> Any: ...


class InvokerSession(ErrorSession, Protocol):
    """What the invoker needs of its session."""

    trusted: bool
    base_dir: Path | None
    _invocations: dict[str, Invocation]

    def _spawn(self, chart: Chart, invokeid: str, values: dict[str, Any], base_dir: Path | None) -> Interpreter: ...

    def _child_chart(self, inv: CInvoke) -> tuple[Chart, Path | None]: ...


class MicrostepSession(ErrorSession, Protocol):
    """What a microstep (exiting and entering states) needs of its session."""

    running: bool
    final_state: str | None
    internal: deque[Event]
    _config: set[CState]
    _atomic: list[CState] | None
    _history: History
    _to_invoke: set[CState]
    _data_ready: set[CState]
    _invocations: dict[str, Invocation]
    _step: MacroStep | None
    _observers: list[Callable[[MetaEvent], None]]
    _late: bool

    def _notify(self, name: str, **data: Any) -> None: ...

    def _bind(self, state: CState) -> None: ...

    def _cancel_invokes(self, state: CState) -> None: ...

    def _done_data(self, values: Any) -> Any: ...

    def _exits(self, t: CTransition) -> set[CState]: ...

    def _exit_set(self, transitions: list[CTransition]) -> list[CState]: ...

    def _exit_states(self, enabled: list[CTransition]) -> None: ...

    def _exit_one(self, s: CState) -> None: ...

    def _enter(self, enabled: list[CTransition]) -> None: ...

    def _entered_final(self, s: CState) -> None: ...

    def _in_final(self, s: CState) -> bool: ...

    def _donedata(self, s: CState) -> Any: ...

    def _entry_set(self, enabled: list[CTransition]) -> EntrySet: ...
