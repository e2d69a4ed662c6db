"""The descriptions as plain data: devices, processes, tasks and cells (paper section 5).

Tasks are in :mod:`plugnproduce.description.tasks` and places in files in
:mod:`plugnproduce.description.where`; both are named here too.

Nothing here does I/O; :mod:`plugnproduce.description.loader` builds these objects
from files, and every object remembers the file and line it came from so that a
finding can say where it rests.
"""

from __future__ import annotations

import dataclasses
from dataclasses import field
from typing import TYPE_CHECKING, Literal

from plugnproduce.deferred import dataclass
from plugnproduce.description.flow import Branch as Branch
from plugnproduce.description.flow import Loop as Loop
from plugnproduce.description.tasks import Link as Link
from plugnproduce.description.tasks import Step as Step
from plugnproduce.description.tasks import Task as Task
from plugnproduce.description.tasks import plain_value as plain_value
from plugnproduce.description.where import Where as Where
from plugnproduce.errors import UnknownName
from plugnproduce.statechart.model import Chart

if TYPE_CHECKING:
    from plugnproduce.description.quantities.durations import RequestDuration

Protocol = Literal["xirp", "upnp", "opcua"]
PROTOCOLS: tuple[Protocol, ...] = ("xirp", "upnp", "opcua")


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

    def __hash__(self) -> int:
        """Of its names, chart file and initial state only: equal devices hash alike, and a fact cache keyed by a
        device does not walk its states and transitions (nor make their classes' methods) at every look-up."""
        return hash((self.id, self.iri, self.chart_file, self.initial, self.reported_state))

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
    durations: tuple[RequestDuration, ...] = ()
    """Declared request durations (``pnp:hasDuration``); the chart's delays count for the others."""

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

    def __hash__(self) -> int:
        """Of its names and chart file only: equal processes hash alike, and a fact cache keyed by the processes
        does not walk their roles and parameters at every look-up."""
        return hash((self.id, self.iri, self.chart_file))

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
