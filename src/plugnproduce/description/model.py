"""The descriptions as plain data: devices, processes, tasks and cells (paper section 5).

Nothing here does I/O; :mod:`plugnproduce.description.loader` builds these objects
from files, and every object remembers the file and line it came from so that a
finding can say where it rests.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

from plugnproduce.description.flow import Branch as Branch
from plugnproduce.description.flow import Loop as Loop
from plugnproduce.description.flow import enclosing, outermost_first, path_name
from plugnproduce.errors import UnknownName
from plugnproduce.statechart.model import Chart

Protocol = Literal["xirp", "upnp", "opcua"]
PROTOCOLS: tuple[Protocol, ...] = ("xirp", "upnp", "opcua")


@dataclass(frozen=True)
class Where:
    """A place in a description file."""

    file: str
    line: int | None = None

    def __str__(self) -> str:
        return self.file if self.line is None else f"{self.file}:{self.line}"


@dataclass(frozen=True)
class Command:
    """A device command from the device's side: wait for a request, or send an event."""

    protocol: str
    kind: Literal["request", "event"]
    name: str

    @property
    def event(self) -> str:
        """The SCXML event name, e.g. ``xirp.request.Open``."""
        return f"{self.protocol}.{self.kind}.{self.name}"

    @classmethod
    def parse(cls, event: str) -> Command | None:
        """The command an event name stands for, or None for an internal event."""
        parts = event.split(".", 2)
        if len(parts) == 3 and parts[0] in PROTOCOLS and parts[1] in ("request", "event"):
            return cls(parts[0], parts[1], parts[2])  # type: ignore[arg-type]
        return None


@dataclass(frozen=True)
class ChartState:
    """A state of a Device State Chart, with the ontology concept it is annotated with.

    In a chart with compound states, the states a device can be in are the atomic ones; each has its
    own concept and those of the compound states around it (:mod:`plugnproduce.description.hierarchy`).
    """

    id: str
    concept: str | None
    """Its own concept, else the nearest enclosing state's."""
    line: int | None
    concepts: tuple[str, ...] = ()
    """Every concept it has: its own, then the enclosing states', nearest first (empty: just :attr:`concept`)."""
    within: tuple[str, ...] = ()
    """The compound states around it, outermost first."""

    @property
    def every_concept(self) -> tuple[str, ...]:
        """Its own concept and those of the compound states around it."""
        return self.concepts or ((self.concept,) if self.concept else ())


@dataclass(frozen=True)
class ChartTransition:
    """A transition of a Device State Chart with the device commands on it."""

    source: str
    target: str
    event: str | None
    """Triggering event: a request (``xirp.request.Open``), an internal event, or None."""
    sends: tuple[Command, ...]
    """Protocol events the device sends while taking it (including the target's onentry)."""
    accepts: tuple[str, ...]
    """Quantity concept IRIs a request carries (``pnp:accepts``)."""
    line: int | None
    concept: str | None = None
    """The concept the transition is annotated with (``pnp:concept``), e.g. ``pnp:SafeStop``."""
    origin: str | None = None
    """The state the transition is written on: :attr:`source` or a compound state around it (None: the source)."""

    @property
    def request(self) -> Command | None:
        """The request this transition waits for, if any."""
        cmd = Command.parse(self.event) if self.event else None
        return cmd if cmd is not None and cmd.kind == "request" else None


@dataclass(frozen=True)
class Argument:
    """The contract of one argument of a device request (``pnp:RequestArgument``): the device's own terms.

    A quantity a request ``pnp:accepts`` with no declared argument is required, of any type, unit
    and value (what ``pnp:accepts`` alone always meant).
    """

    request: str
    """The request's name (``Close`` for ``xirp.request.Close``)."""
    quantity: str
    required: bool = True
    datatype: str = ""
    unit: str = ""
    minimum: float | None = None
    maximum: float | None = None
    reach: float | None = None
    """For a pose: the largest distance of its position from the device's base, in metres."""
    default: object = None
    where: Where | None = None

    @property
    def needed(self) -> bool:
        """Whether a process must supply it: required and without a default of the device's own."""
        return self.required and self.default is None


@dataclass(frozen=True)
class DeviceDescription:
    """A device: its metadata and its Device State Chart."""

    id: str
    iri: str
    label: str
    classes: tuple[str, ...]
    declared_skills: tuple[str, ...]
    protocol: str
    endpoint: str
    chart_file: str
    initial: str
    states: tuple[ChartState, ...]
    transitions: tuple[ChartTransition, ...]
    where: Where
    command_timeout: float = 10.0
    cost: float = 0.0
    skills: tuple[str, ...] = ()
    """Every skill of the device after reasoning (declared, implied by class, super-skills)."""
    chart: Chart = field(default_factory=Chart, compare=False, repr=False)
    """The parsed Device State Chart (``chart_file`` as read by the one SCXML reader)."""
    reported_state: bool = False
    """Whether :attr:`initial` is the state the device reported (a live cell), not its chart's initial state."""
    compounds: tuple[ChartState, ...] = ()
    """The compound states of its chart (their own concepts); :attr:`states` are the atomic ones."""
    stops: tuple[ChartTransition, ...] = ()
    """The safe-stop transitions (a request annotated ``pnp:SafeStop``): sent only to stop the device,
    never planned with, so they are not among :attr:`transitions`."""

    def stop_from(self, state_id: str) -> ChartTransition | None:
        """The safe-stop request the device takes in state ``state_id``, if it takes one there."""
        return next((t for t in self.stops if t.source == state_id and t.request is not None), None)

    def reported(self, state_id: str) -> DeviceDescription:
        """The device as it reports itself to be now: in state ``state_id`` (replacing its chart's initial state
        wherever a plan starts from it)."""
        self.state(state_id)
        return dataclasses.replace(self, initial=state_id, reported_state=True)
    arguments: tuple[Argument, ...] = ()
    """Declared contracts of its requests' arguments (``pnp:hasArgument``)."""

    def answer_to(self, request: str) -> str | None:
        """The event the device answers ``request`` with at once: the one protocol event every transition taking
        the request sends (in the transition or the target's onentry), or None."""
        sent = {tuple(c.name for c in t.sends if c.kind == "event")
                for t in (*self.transitions, *self.stops) if t.request is not None and t.request.name == request}
        return next(iter(sent))[0] if len(sent) == 1 and len(next(iter(sent))) == 1 else None

    def argument(self, request: str, quantity: str) -> Argument:
        """The contract of a request's argument: the declared one, else required with no limits."""
        for a in self.arguments:
            if a.request == request and a.quantity == quantity:
                return a
        return Argument(request, quantity)

    def state(self, state_id: str) -> ChartState:
        """The chart state called ``state_id``."""
        for s in self.states:
            if s.id == state_id:
                return s
        raise UnknownName("state", state_id, (s.id for s in self.states), owner=f"device {self.id}")


@dataclass(frozen=True)
class RegionState:
    """A state of one role's region of a General Process State Chart."""

    id: str
    concept: str
    line: int | None
    params: tuple[str, ...] = ()
    """Parameter names consumed on the way into this state (``pnp:params``)."""
    waits_for: str | None = None
    """State id of another region this state waits for (``In('...')``) before it is entered."""
    outcomes: tuple[str, ...] = ()
    """Outcome concepts a region's final state may be reached with (``pnp:outcomes``), which its device
    reports as the ``outcome`` value of the event that ends it."""


@dataclass(frozen=True)
class Role:
    """A role of a process: the skill it requires and the states its region visits."""

    name: str
    iri: str
    required_skill: str
    region: tuple[RegionState, ...]
    where: Where

    @property
    def start_concept(self) -> str:
        """The state concept the device must be in when the process starts."""
        return self.region[0].concept

    @property
    def end_concept(self) -> str:
        """The state concept the device is left in."""
        return self.region[-1].concept


@dataclass(frozen=True)
class Parameter:
    """A process parameter the user fills in on the HMI."""

    name: str
    iri: str
    role: str
    quantity: str
    datatype: str
    unit: str
    minimum: float | None
    maximum: float | None
    default: object
    where: Where


@dataclass(frozen=True)
class Output:
    """A value a process gives back (``pnp:hasOutput``): its role's device reports it as an event payload."""

    name: str
    iri: str
    role: str
    quantity: str
    datatype: str
    unit: str
    where: Where


@dataclass(frozen=True)
class ProcessDescription:
    """A process: roles, parameters and its General Process State Chart."""

    id: str
    iri: str
    label: str
    comment: str
    classes: tuple[str, ...]
    roles: tuple[Role, ...]
    parameters: tuple[Parameter, ...]
    chart_file: str
    where: Where
    chart: Chart = field(default_factory=Chart, compare=False, repr=False)
    """The parsed General Process State Chart."""
    outputs: tuple[Output, ...] = ()
    """The values the process gives back, which later steps of a task may take as parameters."""

    def role(self, name: str) -> Role:
        """The role called ``name``."""
        for r in self.roles:
            if r.name == name:
                return r
        raise UnknownName("role", name, (r.name for r in self.roles), owner=f"process {self.id}")

    def parameter(self, name: str) -> Parameter:
        """The parameter called ``name``."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise UnknownName("parameter", name, (p.name for p in self.parameters), owner=f"process {self.id}")

    @property
    def outcomes(self) -> tuple[str, ...]:
        """The outcome concepts the process may end with (each leaves its roles' devices in their end states)."""
        return tuple(o for r in self.roles for o in r.region[-1].outcomes)

    def outcome_role(self) -> Role | None:
        """The role whose device reports the outcome, if the process has outcomes."""
        return next((r for r in self.roles if r.region[-1].outcomes), None)

    def output(self, name: str) -> Output:
        """The output called ``name``."""
        for o in self.outputs:
            if o.name == name:
                return o
        raise UnknownName("output", name, (o.name for o in self.outputs), owner=f"process {self.id}")


@dataclass(frozen=True)
class Link:
    """A parameter value taken from an earlier step's output (``{from: localize, output: part_pose}``)."""

    step: str
    """The ``name:`` of the step that produces the value."""
    output: str
    offset: tuple[float, ...] | None = None
    """For a pose: added to the output, item by item (``[0, 0, 0.2, 0, 0, 0]``: 0.2 m above it)."""

    def to_plain(self) -> dict[str, object]:
        """The link as the task file writes it."""
        plain: dict[str, object] = {"from": self.step, "output": self.output}
        if self.offset is not None:
            plain["offset"] = list(self.offset)
        return plain

    def applied(self, value: object) -> object:
        """The output ``value`` with the offset added (as it is when it is no pose of the offset's length)."""
        if self.offset is None or not isinstance(value, list | tuple) or len(value) != len(self.offset) or \
                not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
            return value
        return [v + o for v, o in zip(value, self.offset, strict=True)]


def plain_value(value: object) -> object:
    """A parameter value as YAML and JSON hold it (a link becomes its mapping)."""
    return value.to_plain() if isinstance(value, Link) else value


@dataclass(frozen=True)
class Step:
    """One process command of a task, with its role bindings and parameter values."""

    index: int
    """1-based position in the expanded task."""
    command: str
    bind: dict[str, str] = field(default_factory=dict)
    params: dict[str, object] = field(default_factory=dict)
    line: int | None = None
    param_lines: dict[str, int] = field(default_factory=dict, compare=False)
    """Line of each parameter value in the task file."""
    name: str | None = None
    """The step's name (``name:``), by which later steps take its outputs."""

    def links(self) -> dict[str, Link]:
        """The parameters whose values come from earlier steps' outputs."""
        return {n: v for n, v in self.params.items() if isinstance(v, Link)}

    def values(self) -> dict[str, object]:
        """The parameters given as values (links left out)."""
        return {n: v for n, v in self.params.items() if not isinstance(v, Link)}


@dataclass(frozen=True)
class Task:
    """A task description: an ordered list of process commands, some of them in loops and branches
    (:mod:`plugnproduce.description.flow`)."""

    MAX_STEPS = 10_000
    """Most steps a task may have once its repeats are expanded."""

    name: str
    steps: tuple[Step, ...]
    file: str
    description: str = ""
    repeat: int = 1
    loops: tuple[Loop, ...] = ()
    branches: tuple[Branch, ...] = ()

    @classmethod
    def repeated(cls, name: str, one_round: Sequence[Step], file: str, description: str = "",
                 repeat: int = 1) -> Task:
        """The task whose steps are ``one_round`` done ``repeat`` times, numbered from 1 in that order.

        The one place a task's repeats are expanded (task files and the HTTP API's tasks alike).
        """
        n = len(one_round)
        steps = tuple(dataclasses.replace(s, index=r * n + i + 1) for r in range(repeat)
                      for i, s in enumerate(one_round))
        return cls(name, steps, file, description, repeat)

    def one_round(self) -> tuple[Step, ...]:
        """The steps as written once, before the repeats."""
        return self.steps[: len(self.steps) // max(self.repeat, 1)]

    def loop_at(self, index: int) -> Loop | None:
        """The outermost loop whose body (either copy) holds step position ``index``, if any."""
        return next(iter(self.loops_at(index)), None)

    def loops_at(self, index: int) -> tuple[Loop, ...]:
        """The loops whose bodies (either copy) hold step position ``index``, outermost first."""
        return enclosing(self.loops, index)

    def loop_starting(self, index: int, end: int) -> Loop | None:
        """The outermost loop that starts at step position ``index`` and ends by position ``end``, if any."""
        return next((lp for lp in outermost_first(self.loops) if lp.entry == index and lp.last <= end), None)

    def branches_of(self, index: int) -> tuple[Branch, ...]:
        """The branches on the outcome of the step at position ``index``, in the order written."""
        return tuple(b for b in self.branches if b.step == index)

    def path(self, index: int) -> str | None:
        """The path step position ``index`` lies on (``loop iteration 1, branch NoPartFound at step 2``)."""
        return path_name(self.loops, self.branches, index)

    def where(self, step: Step, parameter: str | None = None) -> Where:
        """The place of a step (or of one of its parameter values) in the task file."""
        return Where(self.file, step.param_lines.get(parameter, step.line) if parameter else step.line)


@dataclass(frozen=True)
class Cell:
    """A set of devices."""

    name: str
    devices: tuple[DeviceDescription, ...]
    file: str | None = None

    def device(self, device_id: str) -> DeviceDescription:
        """The device called ``device_id``."""
        for d in self.devices:
            if d.id == device_id:
                return d
        raise UnknownName("device", device_id, (d.id for d in self.devices), owner=f"cell {self.name}")

    def without(self, device_id: str) -> Cell:
        """The same cell with one device unplugged."""
        return Cell(self.name, tuple(d for d in self.devices if d.id != device_id), self.file)

    def reported(self, states: dict[str, str]) -> Cell:
        """The same cell with each device named in ``states`` in the state it reported
        (:meth:`DeviceDescription.reported`)."""
        return Cell(self.name, tuple(d.reported(states[d.id]) if d.id in states else d for d in self.devices),
                    self.file)

    def with_device(self, device: DeviceDescription) -> Cell:
        """The same cell with one more device plugged in (replacing one of the same id)."""
        rest = tuple(d for d in self.devices if d.id != device.id)
        return Cell(self.name, rest + (device,), self.file)
