"""The closed world as a transition system: the Task State Chart and every device's chart, each a
session of the project's one SCXML runtime, joined by message channels.

A :class:`World` is one global configuration: each session's snapshot, the requests on their way
from the controller to each device and the events on their way back (each channel in order, as
over one connection). A :class:`Move` is one thing that may happen next; which one does is left
open, as the devices' delays are unknown:

- ``request``: a device receives the next request the controller sent it;
- ``event``: the controller receives the next event a device sent;
- ``timer``: one of a device's delayed sends arrives (its own motion ending, say);
- ``own``: a device takes an event it sent itself without delay (these come first).

An event that reports the step's ``outcome`` may report any outcome the step's process declares
(which one a device finds is not in its chart): each is a move of its own, so every branch and
every way out of a loop is explored.

The controller's own timers (a device's command timeout) never fire: the devices are taken to
behave as their charts say, so a controller that would wait for ever is a deadlock, not a timeout.
The controller sends itself nothing else (the Task State Chart sends only requests and its timers), so
it only ever moves on an event of a device.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

from plugnproduce.chartnames import DONE, STEP
from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.model import PROTOCOLS, Cell, ChartTransition, DeviceDescription
from plugnproduce.errors import ExecutionError
from plugnproduce.ontology.iris import local_name
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.events import Event, EventData, MacroStep
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.statechart.runtime.snapshot import Snapshot, assigned_variables, fire, restore, take
from plugnproduce.verification.arguments import argument_problems

CONTROLLER = "controller"


@dataclass(frozen=True)
class Message:
    """A request or an event on its way: its name and arguments."""

    name: str
    data: Any

    @property
    def key(self) -> Hashable:
        """What tells it from another message."""
        return (self.name, repr(self.data))


@dataclass(frozen=True)
class World:
    """One global configuration of the closed world."""

    controller: Snapshot
    devices: tuple[Snapshot, ...]
    requests: tuple[tuple[Message, ...], ...]
    """Per device (in cell order), the requests the controller sent it that it has not received yet."""
    events: tuple[tuple[Message, ...], ...]
    """Per device, the events it sent that the controller has not received yet."""
    key: Hashable = field(compare=False)


@dataclass(frozen=True)
class Move:
    """One thing that may happen next (see the module's description)."""

    kind: Literal["request", "event", "timer", "own"]
    session: str
    """The session that acts: ``controller`` or a device id."""
    device: str = ""
    """The device the event comes from (``event`` moves)."""
    name: str = ""
    """The event that arrives."""
    timer: int = -1
    """Which delayed send arrives (``timer`` moves)."""
    outcome: str = ""
    """The outcome the event reports (``event`` moves of an event that reports one)."""


@dataclass(frozen=True)
class Violation:
    """What went wrong in a move: its kind and one sentence."""

    kind: Literal["refused", "argument", "unexpected", "failed", "error", "deadlock"]
    message: str


def states_of(session: Snapshot) -> str:
    """Where a session is: its active states, outermost first, or the final state its chart ended in."""
    return "/".join(s for s in (*session.states, session.final_state) if s)


class _Outbox:
    """An I/O processor that keeps what a session sends over the device protocols."""

    def __init__(self) -> None:
        self.sent: list[tuple[str | None, Event]] = []

    def send(self, event: Event, target: str | None, type: str) -> None:  # noqa: A002 - the SCXML name
        """Keep the event for the channel it goes to."""
        self.sent.append((target, event))


class ClosedWorld:
    """The sessions of a generated task on the devices of a cell, driven one move at a time."""

    def __init__(self, generated: GeneratedTask, cell: Cell):
        self.generated = generated
        self.devices: tuple[DeviceDescription, ...] = tuple(cell.devices)
        self._index = {d.id: i for i, d in enumerate(self.devices)}
        self._outbox = _Outbox()
        self.controller = Interpreter(generated.chart, clock=ManualClock(),
                                      io_processors={p: self._outbox for p in PROTOCOLS})
        self.sessions = [Interpreter(d.chart, clock=ManualClock(), io_processors={d.protocol: self._outbox})
                         for d in self.devices]
        self._vars = assigned_variables(self.controller)
        self._device_vars = [assigned_variables(s) for s in self.sessions]
        # by the state a transition is written on: a compound state's transition is taken from every state inside it
        self._transitions = [{(t.origin or t.source, t.event): t for t in d.transitions} for d in self.devices]

    def start(self) -> tuple[World, Violation | None]:
        """The initial world: every session started."""
        self.controller.start()
        requests = self._requests([[] for _ in self.devices])
        events: list[list[Message]] = [[] for _ in self.devices]
        for i, session in enumerate(self.sessions):
            session.start()
            self._device_events(i, events)  # what it sent as it started, on its own channel
        world = self._world(take(self.controller, self._vars),
                            tuple(take(s, v) for s, v in zip(self.sessions, self._device_vars, strict=True)),
                            requests, events)
        return world, self._ended(world.controller)

    def moves(self, world: World) -> Iterator[Move]:
        """Every move possible in ``world``, in a fixed order."""
        if world.controller.final_state is not None:
            return
        for i, device in enumerate(self.devices):
            snap = world.devices[i]
            if snap.external:
                yield Move("own", device.id, name=snap.external[0].name)
                continue
            if world.requests[i]:
                yield Move("request", device.id, name=world.requests[i][0].name)
            for n, pending in enumerate(snap.delayed):
                yield Move("timer", device.id, name=pending.event.name, timer=n)
        for i, device in enumerate(self.devices):
            if world.events[i]:
                name = f"{device.id}.{world.events[i][0].name}"
                data = world.events[i][0].data
                if isinstance(data, EventData) and "outcome" in data and self._outcomes(world):
                    yield from (Move("event", CONTROLLER, device.id, name, outcome=o) for o in self._outcomes(world))
                else:
                    yield Move("event", CONTROLLER, device.id, name)

    def _outcomes(self, world: World) -> tuple[str, ...]:
        """The outcomes the process of the step the controller is in declares."""
        steps = self.generated.steps
        ended = self.steps_ended(world)
        return tuple(local_name(o) for o in steps[ended].process.outcomes) if ended < len(steps) else ()

    def apply(self, world: World, move: Move) -> tuple[World, Violation | None]:
        """The world after ``move``, and what went wrong in it (None: nothing)."""
        requests = [list(q) for q in world.requests]
        events = [list(q) for q in world.events]
        if move.session == CONTROLLER:
            return self._controller_move(world, move, requests, events)
        i = self._index[move.session]
        session, variables = self.sessions[i], self._device_vars[i]
        restore(session, world.devices[i], variables)
        violation = None
        try:
            if move.kind == "timer":
                fire(session, world.devices[i].delayed[move.timer])
            elif move.kind == "own":
                session.execute_once()
            else:
                message = requests[i].pop(0)
                session.external.append(Event(message.name, message.data))
                violation = self._received(i, world.devices[i], message, session.execute_once())
        except ExecutionError as exc:
            violation = Violation("error", f"device {move.session}: {exc}")
        self._device_events(i, events)
        devices = list(world.devices)
        devices[i] = take(session, variables)
        return self._world(world.controller, tuple(devices), requests, events), violation

    def _controller_move(self, world: World, move: Move, requests: list[list[Message]],
                         events: list[list[Message]]) -> tuple[World, Violation | None]:
        restore(self.controller, world.controller, self._vars)
        violation = None
        try:
            message = events[self._index[move.device]].pop(0)
            data = EventData({**message.data, "outcome": move.outcome}) if move.outcome else message.data
            self.controller.external.append(Event(move.name, data))
            step = self.controller.execute_once()
            if step is not None and not step.transitions:
                violation = Violation("unexpected", f"the controller does not wait for {move.name} "
                                                    "where it is: the run would stop with a fault")
        except ExecutionError as exc:
            violation = Violation("error", f"the task chart: {exc}")
        snap = take(self.controller, self._vars)
        return self._world(snap, world.devices, self._requests(requests), events), violation or self._ended(snap)

    def _received(self, i: int, before: Snapshot, message: Message, step: MacroStep | None) -> Violation | None:
        """A request refused where the device is, or one missing an argument the transition takes."""
        device = self.devices[i]
        if step is None or not step.transitions:
            return Violation("refused", f"device {device.id} in state {states_of(before)} refuses {message.name}: "
                                        "its chart has no transition for it there")
        taken = step.transitions[0]
        transition: ChartTransition | None = self._transitions[i].get((taken.source, message.name))
        problems = argument_problems(device, transition, message.data) if transition is not None else []
        if problems:
            return Violation("argument", f"device {device.id}: {message.name} " + "; ".join(problems))
        return None

    def _requests(self, requests: list[list[Message]]) -> tuple[tuple[Message, ...], ...]:
        """The channels with the requests the controller just sent appended."""
        for target, event in self._outbox.sent:
            i = self._index.get(target or "")
            if i is not None:
                requests[i].append(Message(event.name, EventData(event.data or {})))
        self._outbox.sent.clear()
        return tuple(tuple(q) for q in requests)

    def _device_events(self, i: int, events: list[list[Message]]) -> None:
        for _, event in self._outbox.sent:
            events[i].append(Message(event.name, EventData(event.data or {})))
        self._outbox.sent.clear()

    def _ended(self, controller: Snapshot) -> Violation | None:
        if controller.final_state is None or controller.final_state == DONE:
            return None
        return Violation("failed", f"the task ends in {controller.final_state}, not {DONE}")

    def _world(self, controller: Snapshot, devices: tuple[Snapshot, ...], requests: Sequence[Sequence[Message]],
               events: Sequence[Sequence[Message]]) -> World:
        to_devices = tuple(tuple(q) for q in requests)
        to_controller = tuple(tuple(q) for q in events)
        key = (controller.key, tuple(d.key for d in devices), tuple(tuple(m.key for m in q) for q in to_devices),
               tuple(tuple(m.key for m in q) for q in to_controller))
        return World(controller, devices, to_devices, to_controller, key)

    def devices_index(self, device: str) -> int:
        """The position of a device's session and channels."""
        return self._index[device]

    def steps_ended(self, world: World) -> int:
        """How many steps of the task the controller has ended in ``world``."""
        return int(world.controller.data[self._vars.index(STEP)])  # every Task State Chart counts its steps

    def deadlock(self, world: World) -> Violation:
        """Why nothing can happen in ``world``: what the controller waits for and where the devices are."""
        devices = ", ".join(f"{d.id} in {states_of(s)}" for d, s in zip(self.devices, world.devices, strict=True))
        # the controller's own timeout and error transitions are on the task's outer state, never on an atomic one
        waits = sorted({e for s in world.controller.config if s.is_atomic for t in s.evented for e in t.node.events})
        return Violation("deadlock", f"deadlock: the controller waits for {' or '.join(waits) or 'nothing'} "
                                     f"and no device will send it ({devices})")
