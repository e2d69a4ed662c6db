"""Running a Task State Chart against the devices of a cell (paper section 6.3).

The task chart runs in the project's SCXML runtime. Its ``<send type="xirp|upnp|opcua">``
commands go out over the device links; device events come back as
``DEVICE.PROTOCOL.event.NAME``. Every command, event, device state and step is written
to the run's journal before the run goes on.

A fault stops the run: a device that does not answer or does not report in time
(the chart's own ``timeout.DEVICE`` timers), refuses a command, loses its connection,
sends a malformed or duplicated message, or sends an event the task does not wait
for. The chart is then sent ``error.fault`` and leaves every state for ``failed``;
no further command goes out, and the report names the step, device, the state the
controller last saw it in, and the message. A command's answer is a fault of the step
that sent it, with the state its device was in then: a response that never comes is
found even when the chart has already reached its end (the run waits for every
answer, each bounded by its device's command timeout).

A run that ends by a fault or a stop (the operator's, SIGINT, SIGTERM) stops the
devices safely: each device is asked its state, sent the safe-stop request its chart
takes there (a transition annotated ``pnp:SafeStop``), and asked its state again;
each answer is journalled (``stop`` records) before the ``end`` record.
"""

from __future__ import annotations

import asyncio
import hashlib
from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from plugnproduce.chartnames import DONE, STEP, branch_variable
from plugnproduce.codegen import GeneratedTask
from plugnproduce.description.model import PROTOCOLS, Cell, Command
from plugnproduce.description.taskfile import task_to_yaml
from plugnproduce.errors import ExecutionError, PlugNProduceError, ProtocolConnectionError, ProtocolTimeout
from plugnproduce.executor import outcomes, values
from plugnproduce.executor.chartmap import chart_map
from plugnproduce.executor.journal import Journal, JournalWriteError
from plugnproduce.executor.links import DeviceLink, open_link
from plugnproduce.executor.monitor import Breach, Monitor
from plugnproduce.executor.report import Fault, RunReport
from plugnproduce.executor.safestop import stop_safely
from plugnproduce.ontology.iris import local_name
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.runtime.events import STATE_ENTERED, Event, EventData, MacroStep, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.statechart.runtime.loop import ChartLoop

RecordObserver = Callable[[dict[str, Any]], None]
"""Called with each journal record as soon as it is written."""

FAULT_EVENT = "error.fault"
MAX_UNANSWERED = 1000
"""Requests to one device not yet answered (sent, or held back behind earlier ones) that a task chart may queue. A
chart waits for its device's event after each request, so it has one or two; more means that eventless
transitions send in a cycle (the chart never settles): a fault of the chart, before the interpreter's own
microstep bound, and nothing more is queued."""


class TaskRun:
    """One run of a generated task in a cell whose devices carry their real endpoints."""

    def __init__(self, generated: GeneratedTask, cell: Cell, journal_path: Path,
                 observer: RecordObserver | None = None, prefixes: Mapping[str, str] | None = None,
                 preamble: tuple[tuple[str, dict[str, Any]], ...] = (), *, speed: float | None = None) -> None:
        """``preamble``: records (kind, fields) journalled right after ``start``, before anything goes out (a
        resumed run's ``stopped``, ``replan`` and ``continue``); ``speed``: how much faster than real time the
        devices work when they are simulated, journalled with ``start`` (None: real devices, not journalled)."""
        self.generated = generated
        self.speed = speed
        self._preamble = preamble
        self.cell = cell
        self.journal_path = journal_path
        self._observer = observer
        data = generated.task_chart()
        self._digest = hashlib.sha256(data).hexdigest()
        chart = parse_chart(data, f"{generated.task.name}.task.scxml")
        self._states = chart_map(chart)
        self._bindings = {s.step.index: dict(s.binding) for s in generated.steps}
        self.interpreter = Interpreter(chart, io_processors={p: self for p in PROTOCOLS})
        self.interpreter.attach(self._on_meta)
        self._loop = ChartLoop(self.interpreter, self._on_step)
        self._journal: Journal | None = None
        self._journal_failed = False
        self._links: dict[str, DeviceLink] = {}
        self._commands: set[asyncio.Task[None]] = set()
        self._last: asyncio.Task[None] | None = None
        """The command sent last: the next one goes out once it is answered."""
        self._monitor = Monitor(generated, cell)
        self._prefixes = dict(prefixes or outcomes.DEFAULT_PREFIXES)
        self._unanswered: dict[str, int] = {}
        """Per device, its commands not yet answered (or held back behind another's): its events and the states
        the chart enters for it wait until they are."""
        self._held: dict[str, list[tuple[int | None, str, dict[str, Any]]]] = {}
        self._unconfirmed: dict[str, list[tuple[int | None, str]]] = {}
        self._late: Fault | None = None
        """A timer that fired while its device's command was not answered yet."""
        self.fault: Fault | None = None
        self._faulted = asyncio.Event()
        self.step: int | None = None
        self.command: str | None = None
        self.device_states: dict[str, str] = {}

    # --- public -----------------------------------------------------------------------

    async def run(self) -> RunReport:
        """Connect to the devices, run the chart to its end, close everything; the report says how it went."""
        with Journal(self.journal_path) as self._journal:
            self._record("start", task=self.generated.task.name, cell=self.cell.name, chart_sha256=self._digest,
                         steps=len(self.generated.steps), devices={d.id: d.endpoint for d in self.cell.devices},
                         task_file=task_to_yaml(self.generated.task), cell_file=self.cell.file,
                         **({} if self.speed is None else {"speed": self.speed}))
            for kind, fields in self._preamble:
                self._record(kind, **fields)
            try:
                await self._connect()
                if self.fault is None:
                    await self._loop.run()
                if self.fault is None:  # the chart is done; the commands not yet answered still may fail it
                    await self._answers()
                if self.fault is None and self._late is not None:
                    self._fail(self._late)
            except ExecutionError as exc:  # the task chart itself broke down: a fault like any other
                self._fail(Fault("chart", str(exc), self.step, self.command))
            finally:
                self._journal_held()
                if self.fault is not None or self.interpreter.final_state != DONE:
                    await stop_safely(self.cell, self._links, self.device_states, self._record)
                for task in self._commands:
                    task.cancel()
                await asyncio.gather(*self._commands, return_exceptions=True)
                await asyncio.gather(*(link.close() for link in self._links.values()), return_exceptions=True)
            outcome = self._outcome()
            end: dict[str, Any] = {"outcome": outcome, "device_states": dict(self.device_states)}
            if self.fault is not None:
                end["reason"] = str(self.fault)
            self._record("end", **end)
        return RunReport(outcome, self.journal_path, self.fault, dict(self.device_states))

    def observed(self, observer: RecordObserver) -> TaskRun:
        """The run, its records passed to ``observer`` from now on (before it starts)."""
        self._observer = observer
        return self

    def stop(self, reason: str = "stopped by the operator") -> None:
        """Stop the run as a fault of kind ``stopped``: no further command goes out."""
        self._fail(Fault("stopped", reason, self.step, self.command))

    def device_lost(self, device: str, reason: str) -> None:
        """A device left the cell (e.g. its byebye was seen) while the run goes on."""
        if device in self._links:
            self._fail(self._fault("lost", device, reason))

    # --- devices --------------------------------------------------------------------------

    async def _connect(self) -> None:
        for device in self.cell.devices:
            try:
                self._links[device.id] = await open_link(device, self._on_event, self._on_lost, self._on_anomaly)
            except PlugNProduceError as exc:
                self._fail(self._fault("lost", device.id, f"cannot connect: {exc}"))
                return

    def send(self, event: Event, target: str | None, type: str) -> None:  # noqa: A002 - the SCXML name
        """The chart's I/O processor: send a device command (it goes out after the macrostep).

        Each argument is first held to the device's contract (:class:`Monitor`): a breach is a fault, and the
        request is not sent. A command goes out only once every command sent before it is answered; after a
        fault nothing goes out: the chart is on its way to ``failed``.
        """
        if self.fault is not None:
            return
        command = Command.parse(event.name)
        if command is None or command.kind != "request" or target is None or target not in self._links:
            raise PlugNProduceError(f"cannot send {event.name!r} to {target!r}: not a request to a device of the cell")
        given = dict(event.data or {})
        # Whatever becomes of the command is told of the step that sent it and the state its device was in then.
        sent = Fault("", "", self.step, self.command, target, self.device_states.get(target), command.name)
        if self._unanswered.get(target, 0) >= MAX_UNANSWERED:
            self._fail(replace(sent, kind="chart", message=f"{self.interpreter.chart.name or 'the task chart'} queued "
                               f"{MAX_UNANSWERED} requests to {target} without waiting for one to be answered: its "
                               "eventless transitions send in a cycle"))
            return
        checked = self._monitor.check(self.step, target, command.name, given, self.interpreter.dm)
        if isinstance(checked, Breach):
            self._fail(replace(sent, kind="contract", message=checked.message(target, command.name),
                               argument=checked.argument))
            return
        used = values.used(self.generated, self.step, target, given, self.interpreter.dm)
        self._unanswered[target] = self._unanswered.get(target, 0) + 1
        task = asyncio.get_running_loop().create_task(self._request(sent, checked, used, self._last))
        self._last = task
        self._commands.add(task)
        task.add_done_callback(self._commands.discard)

    async def _request(self, sent: Fault, params: dict[str, Any], used: list[dict[str, Any]],
                       earlier: asyncio.Task[None] | None) -> None:
        device, name = sent.device or "", sent.request or ""
        try:
            # the command sent before this one, itself sent after the one before it (each bounded by its device's
            # timeout; a fault among them holds this one back for good): a wait of its own, not of all of them,
            # so that many commands queued at once cost each the same
            if earlier is not None:
                await asyncio.wait((earlier,))
            if self.fault is not None:
                return
            self._record("command", step=sent.step, device=device, command=name, params=params)
            for value in used:
                self._record("value", **value)
            await self._send_one(sent, device, name, params)
        finally:
            self._unanswered[device] -= 1
            if not self._unanswered[device] and self.fault is None:
                self._release(device)

    async def _send_one(self, sent: Fault, device: str, name: str, params: Mapping[str, Any]) -> None:
        timeout = self.cell.device(device).command_timeout
        try:
            await self._links[device].request(name, params, timeout)
        except ProtocolTimeout:
            self._fail(replace(sent, kind="timeout", message=f"command {name}: no answer within {timeout:g} s; it "
                               f"was sent, and whether {device} carries it out is not known"))
        except ProtocolConnectionError as exc:
            self._fail(replace(sent, kind="lost", message=f"command {name}: {exc}"))
        except PlugNProduceError as exc:
            self._fail(replace(sent, kind="refused", message=f"command {name}: {exc}"))

    def _release(self, device: str) -> None:
        """Every command to ``device`` is answered: journal the states the chart entered for it meanwhile, and
        hand its events that came meanwhile to the chart."""
        for step, state in self._unconfirmed.pop(device, []):
            self._enter_state(step, device, state)
        for step, name, params in self._held.pop(device, []):
            self._deliver(step, device, name, params)

    async def _answers(self) -> None:
        """Wait until every command sent is answered (each bounded by its timeout) or a fault comes first."""
        answered: asyncio.Future[Any] = asyncio.ensure_future(asyncio.gather(*self._commands,
                                                                            return_exceptions=True))
        faulted: asyncio.Future[Any] = asyncio.ensure_future(self._faulted.wait())
        await asyncio.wait({answered, faulted}, return_when=asyncio.FIRST_COMPLETED)
        faulted.cancel()
        answered.cancel()

    def _on_event(self, device: str, name: str, params: Mapping[str, Any]) -> None:
        if self.fault is not None:
            return
        if self._unanswered.get(device):  # an event before the answer to the command that caused it: wait for it
            self._held.setdefault(device, []).append((self.step, name, dict(params)))
            return
        self._deliver(self.step, device, name, dict(params))

    def _deliver(self, step: int | None, device: str, name: str, params: dict[str, Any]) -> None:
        protocol = self.cell.device(device).protocol
        event = f"{device}.{protocol}.event.{name}"
        self._record("event", step=step, device=device, event=name, params=params)
        params = self._with_outcome(step, device, params)
        if self.fault is not None:
            return
        for value in values.produced(self.generated, step, device, params):
            self._record("value", **value)
        self._monitor.reported(step, device, params)
        self._loop.queue(event, EventData(params))  # its values read as _event.data.NAME too

    def _with_outcome(self, step: int | None, device: str, params: dict[str, Any]) -> dict[str, Any]:
        """``params`` with the outcome the device reports resolved to the local name the chart compares
        (:mod:`~plugnproduce.executor.outcomes`); an outcome its step's process does not declare is a fault."""
        chart = self.generated.steps[step - 1] if step is not None and 1 <= step <= len(self.generated.steps) else None
        role = chart.process.outcome_role() if chart is not None else None
        if chart is None or role is None or chart.binding.get(role.name) != device or outcomes.PARAM not in params:
            return params
        declared = chart.process.outcomes
        resolved = outcomes.resolve(params[outcomes.PARAM], declared, self._prefixes)
        if resolved is None:
            why = outcomes.undeclared(device, params[outcomes.PARAM], chart.process.id, declared)
            self._fail(self._fault("outcome", device, why))
            return params
        return {**params, outcomes.PARAM: local_name(resolved)}

    def _journal_held(self) -> None:
        """The events that came from a device whose command was never answered: known, never acted on."""
        for device, events in self._held.items():
            for step, name, params in events:
                self._record("event", step=step, device=device, event=name, params=params,
                             ignored="it came before the answer to a command, which never came")
        self._held.clear()

    def _on_lost(self, device: str, reason: str) -> None:
        self._fail(self._fault("lost", device, reason))

    def _on_anomaly(self, device: str, what: str) -> None:
        self._fail(self._fault("anomaly", device, what))

    # --- the chart ----------------------------------------------------------------------

    def _on_meta(self, meta: MetaEvent) -> None:
        """A state entered: journal a new step, and a device's new state, in the order they happen."""
        if meta.name != STATE_ENTERED or self.fault is not None:  # after a fault the chart's states say nothing
            return
        info = self._states.get(meta.data["state"])
        if info is None:
            return
        if info.starts_step:
            done, self.step, self.command = self.step, int(self.interpreter.dm[STEP]) + 1, info.command
            self._branch_taken(done, self.step)
            self._record("step", step=self.step, command=info.command, bindings=self._bindings.get(self.step, {}))
        if info.device is not None and info.device_state is not None:
            if self._unanswered.get(info.device):  # known only once the command that leads there is answered
                self._unconfirmed.setdefault(info.device, []).append((self.step, info.device_state))
            else:
                self._enter_state(self.step, info.device, info.device_state)

    def _enter_state(self, step: int | None, device: str, state: str) -> None:
        if self.device_states.get(device) != state:
            self.device_states[device] = state
            self._record("state", step=step, device=device, state=state)

    def _branch_taken(self, done: int | None, starts: int) -> None:
        """After a step with branches, journal which branch the run takes (``branch: null``: none)."""
        branches = self.generated.task.branches_of(done) if done is not None else ()
        if not branches:
            return
        taken = next((b for b in branches if b.first == starts), None)
        self._record("branch", step=done, outcome=self.interpreter.dm.get(branch_variable(done or 0)),
                     branch=local_name(taken.outcome) if taken else None, path=taken.path if taken else None,
                     next=starts)

    def _on_step(self, step: MacroStep) -> None:
        """A macrostep done: a timer that fired, or a device event nothing waited for, is a fault."""
        event = step.event
        if event is None:
            return
        if event.name.startswith("timeout."):
            device = event.name.removeprefix("timeout.")
            late = self._fault("timeout", device, f"no event from {device} within "
                                                  f"{self.cell.device(device).command_timeout:g} s")
            if self._unanswered.get(device):  # its command's own bounded wait tells of it first; if that command
                self._late = self._late or late  # is answered after all, this timeout stands
                return
            self._fail(late)
        elif not step.transitions and event.name != FAULT_EVENT and self.fault is None:
            device = event.name.partition(".")[0]
            self._fail(self._fault("unexpected", device, f"event {event.name.split('.', 3)[-1]} is not what the "
                                                         "task waits for now"))

    def _fault(self, kind: str, device: str, message: str) -> Fault:
        return Fault(kind, message, self.step, self.command, device, self.device_states.get(device))

    def _fail(self, fault: Fault) -> None:
        """Record the first fault and send the chart to ``failed``; later faults are journalled only."""
        first = self.fault is None
        if first:
            self.fault = fault
            self._faulted.set()
        self._record("fault", **fault.to_json(), first=first)
        if first:  # a chart not (or no longer) running never reads it
            self._loop.queue(FAULT_EVENT)

    def _outcome(self) -> str:
        if self.fault is None and self.interpreter.final_state == DONE:
            return "succeeded"
        return "stopped" if self.fault is not None and self.fault.kind == "stopped" else "failed"

    def _record(self, kind: str, **data: Any) -> None:
        assert self._journal is not None
        try:
            record = self._journal.write(kind, **data)
        except JournalWriteError as exc:  # the run must not go on unjournalled: a fault, and the safe stop
            record = exc.record
            if not self._journal_failed:
                self._journal_failed = True
                self._fail(Fault("journal", str(exc), self.step, self.command))
        if self._observer is not None:
            self._observer(record)
