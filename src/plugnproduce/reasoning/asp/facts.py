"""Descriptions → ASP facts (the schema of :mod:`plugnproduce.reasoning.asp.schema`), with provenance.

Devices, processes and tasks each become facts on their own, so a catalogue's devices
are turned into facts once and reused for every configuration they appear in. Chart
reachability (``reach/3``) is left to ASP, as the transitive closure of ``edge/3``; the
one thing computed here is where a role's region *leaves* a device (``leaves/5``),
because that is code generation's own shortest-path choice
(:func:`plugnproduce.description.paths.find_path`) and the plausibility check must
agree with the code that will run.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import field
from typing import TYPE_CHECKING

from plugnproduce.deferred import dataclass
from plugnproduce.description.model import DeviceDescription, ProcessDescription, Role, Task
from plugnproduce.description.quantities.kinds import KINDS
from plugnproduce.errors import UnknownName
from plugnproduce.knowledge.cache import kept_for
from plugnproduce.knowledge.devicecache import kept_facts
from plugnproduce.lazy import lazy_module
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.terms import Atom, program

if TYPE_CHECKING:
    import decimal

    from plugnproduce.description import paths
    from plugnproduce.knowledge import Knowledge
else:  # what makes facts: a command whose facts are all kept in the cache folder reads them without either
    decimal = lazy_module("decimal")
    paths = lazy_module("plugnproduce.description.paths")

DATATYPES = KINDS
"""Declared parameter datatypes → the short names the encodings compare (the contracts' kinds of value)."""

SCALE = 1000
"""Numbers reach ASP as whole thousandths."""
_LIMIT = 2_000_000_000


def milli(value: object) -> int | None:
    """A finite number in whole thousandths (clamped to ASP's range), or None if it is no such number.

    Only ASCII digits make a number (``Decimal`` would also read ``"١٢٠"``); an infinite or NaN value is none.
    """
    if isinstance(value, bool):
        return None
    text = str(value)
    if not text.isascii():
        return None
    try:
        number = decimal.Decimal(text)
    except (decimal.InvalidOperation, ValueError):
        return None
    if not number.is_finite():
        return None
    if abs(number) >= _LIMIT:  # clamped before scaling: 1e308 is not turned into a 309-digit integer
        return _LIMIT if number > 0 else -_LIMIT
    return max(-_LIMIT, min(_LIMIT, int((number * SCALE).to_integral_value())))


def value_kinds(value: object) -> tuple[str, ...]:
    """The datatypes a task's parameter value can be read as."""
    if isinstance(value, bool):
        return ("boolean",)
    if isinstance(value, int):
        return ("integer",)
    if isinstance(value, float | decimal.Decimal):
        return ("decimal", "integer") if float(value).is_integer() else ("decimal",)
    if isinstance(value, str):
        return ("string", "pose") if _pose(value.split()) else ("string",)
    if isinstance(value, list | tuple) and _pose(value):
        return ("pose",)
    return ()


def _pose(items: Sequence[object]) -> bool:
    return len(items) == 6 and all(milli(v) is not None for v in items)


# ------------------------------------------------------------------ devices


def region_walk(device: DeviceDescription, process: ProcessDescription, role: Role, start: str,
                taxonomy: Taxonomy) -> tuple[str, frozenset[tuple[str, str]]] | None:
    """Where playing ``role`` from ``start`` leaves ``device`` (code generation's walk), and the arguments
    (request, quantity) its requests on the way need that the process does not hand them; None if stuck."""
    current, missing = start, set()
    for general in role.region[1:]:
        try:
            given = frozenset(process.parameter(p).quantity for p in general.params)
            path = paths.find_path(device, current, general.concept, taxonomy, given)
        except (paths.NoPath, KeyError):
            return None
        current = path.target
        missing |= {(t.request.name, q) for t in path.steps if t.request for q in t.accepts
                    if q not in given and device.argument(t.request.name, q).needed}
    return current, frozenset(missing)


def region_end(device: DeviceDescription, process: ProcessDescription, role: Role, start: str,
               taxonomy: Taxonomy) -> str | None:
    """The state playing ``role`` from ``start`` leaves ``device`` in, as code generation walks it; None if stuck."""
    walked = region_walk(device, process, role, start, taxonomy)
    return walked[0] if walked is not None else None


def effects(device: DeviceDescription, process: ProcessDescription, taxonomy: Taxonomy) -> list[Atom]:
    """``leaves/5``, ``recovers/4`` and ``missing_arg/5`` for each role of ``process`` the device has the skill for.

    A request on the way that needs an argument the process does not supply (``missing_arg``) keeps
    the device from the role: the request would be refused at run time.
    """
    out: list[Atom] = []
    for role in process.roles:
        if role.required_skill not in device.skills:
            continue
        first: str | None = None
        missing: set[tuple[str, str]] = set()
        for state in device.states:
            if not paths.in_concept(state, role.start_concept, taxonomy):
                continue
            walked = region_walk(device, process, role, state.id, taxonomy)
            if walked is not None:
                out.append(s.Leaves(process.id, role.name, device.id, state.id, walked[0]))
                first = first or walked[0]
                missing |= walked[1]
        if first is not None:
            out.append(s.Recovers(process.id, role.name, device.id, first))
        out += [s.MissingArg(process.id, role.name, device.id, r, q) for r, q in sorted(missing)]
    return out


def device_facts(device: DeviceDescription, taxonomy: Taxonomy,
                 processes: Iterable[ProcessDescription]) -> list[Atom]:
    """Everything the encodings know about one device: skills, chart, price, role effects."""
    d = device.id
    out: list[Atom] = [s.Device(d), s.Cost(d, round(device.cost)), s.Initial(d, device.initial)]
    out += [s.HasSkill(d, k) for k in device.skills]
    for state in device.states:
        out.append(s.ChartState(d, state.id))
        supers = {c for k in state.every_concept for c in taxonomy.superclasses.get(k, frozenset((k,)))}
        out += [s.StateIs(d, state.id, c) for c in sorted(supers)]
    out += [s.Edge(d, t.source, t.target) for t in device.transitions]
    for p in processes:
        out += effects(device, p, taxonomy)
    return out


# ------------------------------------------------------------------ processes


def process_facts(process: ProcessDescription) -> list[Atom]:
    """Roles, required skills, regions in visiting order, and declared parameters of a process."""
    p = process.id
    out: list[Atom] = [s.Process(p), s.NRoles(p, len(process.roles))]
    for k, role in enumerate(process.roles, start=1):
        out += [s.Role(p, role.name), s.RoleOrder(p, k, role.name), s.Requires(p, role.name, role.required_skill)]
        out += [s.RegionState(p, role.name, i, g.concept) for i, g in enumerate(role.region, start=1)]
    for par in process.parameters:
        out.append(s.Param(p, par.name, DATATYPES.get(par.datatype, par.datatype)))
        low, high = milli(par.minimum), milli(par.maximum)
        if par.minimum is not None and low is not None:
            out.append(s.ParamMin(p, par.name, low))
        if par.maximum is not None and high is not None:
            out.append(s.ParamMax(p, par.name, high))
    return out + [s.ParamRole(p, par.name, par.role) for par in process.parameters]


# ------------------------------------------------------------------ tasks and configurations


def task_facts(task: Task, name: str) -> list[Atom]:
    """Steps, explicit bindings and parameter values of a task, called ``name`` in ASP."""
    out: list[Atom] = []
    for step in task.steps:
        i = step.index
        out.append(s.StepFact(name, i, step.command))
        out += [s.Bind(name, i, r, d) for r, d in sorted(step.bind.items())]
        for n, v in sorted(step.values().items()):  # links: see reasoning.dataflow
            out.append(s.Given(name, i, n))
            out += [s.ValueKind(name, i, n, k) for k in value_kinds(v)]
            num = milli(v)
            if num is not None:
                out.append(s.ValueNum(name, i, n, num))
    return out


def config_facts(config: str, devices: Iterable[str]) -> list[Atom]:
    """A configuration and its devices."""
    return [s.Config(config)] + [s.Member(config, d) for d in devices]


# ------------------------------------------------------------------ a cache per knowledge


@dataclass
class FactBook:
    """Facts of the knowledge's taxonomy and processes; device facts are made once per device."""

    knowledge: Knowledge
    _devices: dict[DeviceDescription, str] = field(default_factory=dict)
    _processes: str = ""

    @property
    def taxonomy(self) -> Taxonomy:
        """The knowledge's taxonomy closure."""
        return self.knowledge.taxonomy

    @property
    def processes(self) -> tuple[ProcessDescription, ...]:
        """The knowledge's processes."""
        return self.knowledge.processes

    def process_text(self) -> str:
        """ASP facts of every process."""
        if not self._processes:
            self._processes = kept_for(self.knowledge, "processes",
                                       lambda: program(a for p in self.processes for a in process_facts(p)))
        return self._processes

    def device_text(self, device: DeviceDescription) -> str:
        """ASP facts of one device (cached)."""
        text = self._devices.get(device)
        if text is None:
            text = kept_facts(device, self.knowledge.key,
                              lambda: program(device_facts(device, self.taxonomy, self.processes)))
            self._devices[device] = text
        return text

    def devices_text(self, devices: Iterable[DeviceDescription]) -> str:
        """ASP facts of several devices, each once."""
        unique = {d.id: d for d in devices}
        return "".join(self.device_text(d) for d in unique.values())

    def process(self, command: str) -> ProcessDescription:
        """The process a command names."""
        found = self.knowledge.processes_by_id.get(command)
        if found is None:
            raise UnknownName("process command", command, self.knowledge.processes_by_id)
        return found


_BOOKS: dict[tuple[str, int], FactBook] = {}


def fact_book(knowledge: Knowledge) -> FactBook:
    """The fact cache for the knowledge's taxonomy and processes (kept for the few most recent)."""
    taxonomy, procs = knowledge.taxonomy, knowledge.processes
    key = (taxonomy.digest or str(id(taxonomy)), hash(procs))
    book = _BOOKS.get(key)
    if book is None or book.processes != procs:
        book = FactBook(knowledge)
        if len(_BOOKS) >= 8:
            _BOOKS.pop(next(iter(_BOOKS)))
        _BOOKS[key] = book
    return book
