"""An SCXML runtime with W3C semantics (https://www.w3.org/TR/scxml/#AlgorithmforSCXMLInterpretation).

One synchronous step at a time: :meth:`Interpreter.execute_once` takes the next external
event and runs the whole macrostep (the event's microstep, then eventless transitions and
internal events until the configuration is stable) and returns a
:class:`~plugnproduce.statechart.runtime.events.MacroStep`. Time comes from an injected clock;
delayed sends wait in the session until the clock reaches them. Observers receive meta
events. asyncio lives apart (:class:`plugnproduce.statechart.runtime.loop.ChartLoop`).

The public API (kept stable: the executor and the simulated devices use it):

``Interpreter(chart, *, clock=None, trusted=False, io_processors=None, base_dir=None, session_id=None)``
    A session of a read :class:`~plugnproduce.statechart.model.Chart`, checked first (a
    :class:`~plugnproduce.errors.DescriptionError` names what is broken). ``clock``: where
    time comes from (default :class:`~plugnproduce.statechart.runtime.clock.MonotonicClock`; tests
    use :class:`~plugnproduce.statechart.runtime.clock.ManualClock`). ``trusted``: expressions are
    plain Python and ``<script>`` runs; by default expressions go through the restricted
    evaluator and a ``<script>`` is refused with an :class:`~plugnproduce.errors.ExecutionError`.
    ``io_processors``: ``<send type>`` → an object with ``send(event, target, type)``.
    ``base_dir``: the folder ``src`` files are read from. ``session_id``: ``_sessionid``
    (default: a random one).
``Interpreter.from_file(path, **options)``
    The same for an SCXML file, whose folder is ``base_dir``.
``start()``
    Initialise the datamodel and enter the initial configuration: the first macrostep.
``queue(name_or_event, data=None)``
    Put an external event on the queue; returns the interpreter, to chain.
``execute_once()`` / ``execute()``
    Deliver the delayed sends that are due, then process the next external event: one
    macrostep, or None when there is nothing to do now (starting the session first if
    need be). ``execute()`` repeats it until then and returns the macrosteps.
``next_due()``
    The clock time of the next delayed send (None: none waits): when to execute again.
``running``, ``started``, ``final_state``
    Whether the session has started and still runs; the id of the top-level final state
    it stopped in (None while it runs).
``configuration``, ``is_active(state_id)``
    Ids of the active states in document order (empty once stopped); whether one is active.
``attach(observer)`` / ``detach(observer)``
    Meta events (:class:`~plugnproduce.statechart.runtime.events.MetaEvent`): states entered and
    exited, events consumed and sent, transitions taken, logs and errors.
``datamodel``
    The datamodel's variables, system variables included.

Errors inside the chart (an expression that fails, a send that cannot be delivered) are
not exceptions: as the specification asks, they become ``error.execution`` or
``error.communication`` events in the chart (and ``error`` meta events).
"""
from __future__ import annotations

import logging
import uuid
from collections import deque
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from plugnproduce import collector
from plugnproduce.errors import ExecutionError
from plugnproduce.safeio import read_bytes
from plugnproduce.statechart import gcpause
from plugnproduce.statechart.io.checks import check_structure
from plugnproduce.statechart.io.reader import parse_chart
from plugnproduce.statechart.model import Chart
from plugnproduce.statechart.runtime.clock import Clock, MonotonicClock
from plugnproduce.statechart.runtime.compiled import CompiledChart, CState, CTransition
from plugnproduce.statechart.runtime.datamodel import Datamodel
from plugnproduce.statechart.runtime.dispatch import Dispatcher
from plugnproduce.statechart.runtime.evaluator import EvaluationError, Evaluator, Expr
from plugnproduce.statechart.runtime.events import (
    EVENT_CONSUMED,
    Event,
    IOProcessor,
    MacroStep,
    MetaEvent,
)
from plugnproduce.statechart.runtime.invoke import Invocation, Invoker
from plugnproduce.statechart.runtime.microstep import Microstep, doc_order

log = logging.getLogger("plugnproduce.statechart")

MAX_MICROSTEPS = 100_000
"""Most microsteps one macrostep may take before the chart is stopped as one that never settles."""

Observer = Callable[[MetaEvent], None]
"""Something that receives meta events."""

class Interpreter(Datamodel, Dispatcher, Invoker, Microstep):
    """Runs one SCXML session. ``trusted=False`` (default) restricts expressions and refuses ``<script>``.

    ``io_processors`` maps ``<send type>`` values (``"xirp"``, ``"upnp"``) to objects with
    ``send(event, target, type)``; ``base_dir`` is where ``src`` files are looked up.
    """

    def __init__(self, chart: Chart, *, clock: Clock | None = None, trusted: bool = False,
                 io_processors: Mapping[str, IOProcessor] | None = None, base_dir: str | Path | None = None,
                 session_id: str | None = None):
        check_structure(chart, chart.name or "chart")
        self._setup(chart, clock or MonotonicClock(), trusted, dict(io_processors or {}),
                    Path(base_dir) if base_dir is not None else None, session_id or uuid.uuid4().hex)

    @classmethod
    def from_file(cls, path: str | Path, **options: Any) -> Interpreter:
        """An interpreter for an SCXML file (``src`` files are looked up beside it)."""
        path = Path(path)
        return cls(parse_chart(read_bytes(path), path), base_dir=path.parent, **options)

    def _setup(self, chart: Chart, clock: Clock, trusted: bool, io_processors: dict[str, IOProcessor],
               base_dir: Path | None, session_id: str) -> None:
        self.chart = chart
        self.clock = clock
        self.trusted = trusted
        self.io_processors = io_processors
        self.base_dir = base_dir
        self.session_id = session_id
        with collector.paused():  # a large chart would otherwise pay for collections that find nothing
            self.compiled = CompiledChart(chart, Evaluator(trusted), chart.name or "chart")
        self._holds_gc = False
        self.running = False
        self.started = False
        self.final_state: str | None = None
        self.invokeid: str | None = None
        self.internal: deque[Event] = deque()
        self.external: deque[Event] = deque()
        self.dm: dict[str, Any] = {}
        self._config: set[CState] = set()
        self._atomic: list[CState] | None = None
        self._history: dict[CState, list[CState]] = {}
        self._to_invoke: set[CState] = set()
        self._data_ready: set[CState] = set()
        self._invocations: dict[str, Invocation] = {}
        self._overrides: dict[str, Any] = {}
        self._parent: Interpreter | None = None
        self._sessions: dict[str, Interpreter] = {session_id: self}
        self._observers: list[Observer] = []
        self._step: MacroStep | None = None
        self._late = chart.binding == "late"
        self._init_dispatch()

    def _spawn(self, chart: Chart, invokeid: str, values: dict[str, Any], base_dir: Path | None) -> Interpreter:
        """A child session for ``<invoke>`` (not started)."""
        child = Interpreter.__new__(Interpreter)
        child._setup(chart, self.clock, self.trusted, self.io_processors, base_dir, uuid.uuid4().hex)
        child._parent, child.invokeid, child._overrides = self, invokeid, values
        child._sessions = self._sessions
        self._sessions[child.session_id] = child
        return child

    # --- public API -------------------------------------------------------------------

    @property
    def configuration(self) -> list[str]:
        """Ids of the active states in document order."""
        return [s.id for s in sorted(self._config, key=doc_order)]

    def is_active(self, state_id: str) -> bool:
        """True when the state with this id is active."""
        return self.compiled.by_id.get(state_id) in self._config

    @property
    def datamodel(self) -> dict[str, Any]:
        """The datamodel's variables (system variables included, builtins left out)."""
        return {k: v for k, v in self.dm.items() if k != "__builtins__"}

    def attach(self, observer: Observer) -> None:
        """Send meta events (state entered/exited, event consumed/sent, ...) to ``observer``."""
        self._observers.append(observer)

    def detach(self, observer: Observer) -> None:
        """Stop sending meta events to ``observer``."""
        self._observers.remove(observer)

    def queue(self, event: str | Event, data: Any = None) -> Interpreter:
        """Put an external event on the queue (a name, or an :class:`Event`); returns self to chain."""
        self.external.append(event if isinstance(event, Event) else Event(event, data))
        return self

    def start(self) -> MacroStep:
        """Initialise the datamodel and enter the initial configuration: the first macrostep."""
        if self.started:
            raise ExecutionError(f"session {self.session_id} of {self.chart.name or 'chart'} is already started")
        self.started = self.running = True
        if len(self.compiled.states) + len(self.compiled.transitions) >= gcpause.LARGE_CHART:
            self._holds_gc = True  # released when the session ends: see gcpause
            gcpause.hold()
        step = self._begin(None)
        self._init_datamodel()
        for block in self.compiled.scripts:
            self._run(block)
        root = self.compiled.root
        if root.initial is not None:
            self._enter([root.initial])
        self._stabilize()
        return self._end(step)

    def execute_once(self) -> MacroStep | None:
        """Process the next external event (starting the session first if need be); None if there is none."""
        if not self.started:
            return self.start()
        if not self.running:
            return None
        self._release_due()
        if self._invocations:
            self._pump_children()
        if not self.external:
            if not self.internal:
                return None
            step = self._begin(None)  # errors from delayed deliveries
            self._stabilize()
            return self._end(step)
        event = self.external.popleft()
        step = self._begin(event)
        self._consume(event)
        if self._invocations:
            self._before_event(event)
        enabled = self._select(event.name)
        if enabled:
            self._microstep(enabled)
        self._stabilize()
        return self._end(step)

    def execute(self, max_steps: int = 10_000) -> list[MacroStep]:
        """Run :meth:`execute_once` until there is nothing to do now (at most ``max_steps`` times)."""
        steps = []
        for _ in range(max_steps):
            step = self.execute_once()
            if step is None:
                break
            steps.append(step)
        return steps

    # --- macrostep --------------------------------------------------------------------

    def _begin(self, event: Event | None) -> MacroStep:
        self._step = MacroStep(self.clock.time(), event)
        return self._step

    def _end(self, step: MacroStep) -> MacroStep:
        self._step = None
        return step

    def _stabilize(self) -> None:
        """Eventless transitions and internal events until stable, then start invocations.

        A chart that never settles (eventless transitions or internal events in a cycle) stops
        with :class:`ExecutionError` after :data:`MAX_MICROSTEPS` microsteps of one macrostep.
        """
        budget = MAX_MICROSTEPS
        while True:
            while self.running:
                budget -= 1
                if budget < 0:
                    self.running = False
                    raise ExecutionError(f"{self.chart.name or 'chart'} found no stable configuration after "
                                         f"{MAX_MICROSTEPS} microsteps: its eventless transitions or internal "
                                         "events run in a cycle")
                enabled = self._select(None)
                if not enabled:
                    if not self.internal:
                        break
                    event = self.internal.popleft()
                    self._consume(event)
                    enabled = self._select(event.name)
                if enabled:
                    self._microstep(enabled)
            if not self.running:
                self._exit_interpreter()
                return
            if self._to_invoke:
                self._start_invokes()
            if not self.internal:
                return

    def _consume(self, event: Event) -> None:
        self.dm["_event"] = event
        if self._step is not None:
            self._step.consumed.append(event)
        if self._observers:
            self._notify(EVENT_CONSUMED, event=event)

    def _start_invokes(self) -> None:
        states = sorted(self._to_invoke, key=doc_order)
        self._to_invoke.clear()
        for state in states:
            for inv in state.invokes:
                self._start_invoke(state, inv)

    # --- transition selection ---------------------------------------------------------

    def _atomic_states(self) -> list[CState]:
        if self._atomic is None:
            self._atomic = sorted((s for s in self._config if s.is_atomic), key=doc_order)
        return self._atomic

    def _select(self, name: str | None) -> list[CTransition]:
        """The optimal enabled transition set for event ``name`` (None: eventless transitions)."""
        enabled: list[CTransition] = []
        for state in self._atomic_states():
            t = self._first_enabled(state, name)
            if t is not None and t not in enabled:
                enabled.append(t)
        if len(enabled) > 1:
            return self._without_conflicts(enabled)
        return enabled

    def _first_enabled(self, state: CState, name: str | None) -> CTransition | None:
        """The first transition of the state or its ancestors that the event (None: no event) enables."""
        if name is None:
            for t in state.eventless_chain:
                if t.cond is None or self.holds(t.cond):
                    return t
            return None
        for t in state.evented_chain:
            if t.matches(name) and (t.cond is None or self.holds(t.cond)):
                return t
        return None

    def holds(self, cond: Expr) -> bool:
        """A condition's truth; one that cannot be evaluated is false and raises ``error.execution``."""
        try:
            return bool(cond.evaluate(self.dm))
        except EvaluationError as exc:
            self._error("error.execution", str(exc))
            return False

    def _without_conflicts(self, enabled: list[CTransition]) -> list[CTransition]:
        filtered: list[CTransition] = []
        for t1 in enabled:
            preempted = False
            to_remove = []
            exit1 = self._exits(t1)
            for t2 in filtered:
                if not exit1.isdisjoint(self._exits(t2)):
                    if t1.source in t2.source.descendants:
                        to_remove.append(t2)
                    else:
                        preempted = True
                        break
            if not preempted:
                for t in to_remove:
                    filtered.remove(t)
                filtered.append(t1)
        return filtered

    def _exit_interpreter(self) -> None:
        """Leave every state (onexit runs), cancel invocations, and tell the parent if it was a final state."""
        final = self.compiled.by_id.get(self.final_state) if self.final_state is not None else None
        done = self._donedata(final) if final is not None and self._parent is not None else None
        for s in sorted(self._config, key=doc_order, reverse=True):
            self._exit_one(s)
        self._atomic = None
        self._sessions.pop(self.session_id, None)
        self.release()
        if self._parent is not None and final is not None:
            self._parent._from_child(self.invokeid, Event(f"done.invoke.{self.invokeid}", done))

    def release(self) -> None:
        """Let the garbage collector walk this session's chart again (see :mod:`.gcpause`).

        Done when the session ends; call it for a session abandoned while it runs. Idempotent.
        """
        if self._holds_gc:
            self._holds_gc = False
            gcpause.release()

    def _stop(self) -> None:
        """Cancelled by the parent: leave every state, send nothing back."""
        if self.running:
            self.running = False
            self.final_state = None
            self._exit_interpreter()

