"""What each catalogue device can do, reasoned once per device and reused by every configuration.

The reasoner (clingo over the taxonomy's HermiT closure facts, ``roles.lp``) decides which
roles of which processes a device can play; ``params.lp`` decides which parameter values of
the tasks are bad (they depend on the task alone). Code generation's path search gives, per
device and role, where playing the role leaves the device (``leaves/5``, ``recovers/4``).
All of it is compiled here into plain tables indexed by a device bit, so that a configuration
is an integer (one bit per catalogue device) and :mod:`plugnproduce.batch.feasibility` only does what depends
on the combination of devices.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, Parameter, ProcessDescription, Task
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from plugnproduce.reasoning.asp.facts import device_facts, process_facts, task_facts
from plugnproduce.reasoning.asp.terms import Atom, program
from plugnproduce.reasoning.checks.accepts import accepts
from plugnproduce.reasoning.checks.contracts import normalised, refusal
from plugnproduce.reasoning.checks.plausibility import check

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

_STEP = re.compile(r"step \d+ \([^)]*\): ")
"""Where a check's problem text names its step, before it says what is wrong."""

PR = tuple[str, str]
"""A role of a process: (process, role)."""


@dataclass(frozen=True)
class StepSpec:
    """One step of a task as the batch sees it."""

    index: int
    process: str | None
    """The process command, None when no process has that name."""
    roles: tuple[tuple[str, str | None], ...]
    """The process's roles in role order, each with the device the step names for it (or None)."""
    unknown_roles: tuple[str, ...]
    """Roles the step binds that the process does not have."""
    bad_value: bool
    refusals: tuple[tuple[str, int], ...] = ()
    """Per parameter value given: the role it goes to, and the devices (bit mask) that accept no such quantity."""
    beyond: tuple[tuple[str, int], ...] = ()
    """Per parameter value sent (given or default): the role it goes to, and the devices (bit mask) whose own
    limits refuse it (:mod:`plugnproduce.reasoning.checks.contracts`)."""
    limits: tuple[tuple[str, int, str], ...] = ()
    """Per value and device of :attr:`beyond`: the role, the device's index, and why it refuses the value."""


@dataclass(frozen=True)
class TaskSpec:
    """A task by its name unique in the batch, and its steps."""

    name: str
    steps: tuple[StepSpec, ...]
    flow: Task | None = None
    """The task itself when it has loops, branches or data links: what its paths, loop iterations and links
    need is the full check's (:class:`FullCheck`), run once per answer's key."""


@dataclass(frozen=True)
class FullCheck:
    """The full plausibility check (:mod:`plugnproduce.reasoning.checks.plausibility`) of a task in a configuration."""

    catalogue: tuple[DeviceDescription, ...]
    """The catalogue devices, in bit order."""
    knowledge: Knowledge
    """The taxonomy and processes alone (no libraries, no catalogue): shipped to workers."""

    def findings(self, task: Task, mask: int) -> tuple[tuple[str, int, str, str], ...]:
        """Why ``task`` is not plausible in the configuration ``mask`` (empty: it is), as the check says."""
        devices = tuple(d for n, d in enumerate(self.catalogue) if mask >> n & 1)
        result = check(task, Cell("configuration", devices), self.knowledge)
        return tuple(sorted({(p.kind, p.step, p.role or "", p.device or "") for p in result.problems},
                            key=lambda f: (f[1], f)))

    def limit(self, task: Task, mask: int, finding: tuple[str, int, str, str]) -> str:
        """The check's words for one ``device_limit`` finding of ``task`` in the configuration ``mask``."""
        devices = tuple(d for n, d in enumerate(self.catalogue) if mask >> n & 1)
        result = check(task, Cell("configuration", devices), self.knowledge)
        return "; ".join(_STEP.split(p.text, 1)[-1] for p in result.problems
                         if (p.kind, p.step, p.role or "", p.device or "") == finding)


@dataclass(frozen=True)
class Abilities:
    """The per-device tables of one catalogue, process set and task set (picklable, shipped to workers)."""

    devices: tuple[str, ...]
    """Catalogue device ids, sorted; device ``devices[i]`` is bit ``1 << i``."""
    costs: tuple[int, ...]
    processes: tuple[tuple[str, tuple[str, ...]], ...]
    """Each process with its roles in role order, sorted by process id."""
    players: dict[PR, int]
    """The devices (bit mask) that can play each role."""
    skills: dict[PR, str]
    """The skill each role requires."""
    first: dict[PR, str]
    """The state concept each role's region starts in."""
    initial: tuple[frozenset[str], ...]
    """Each device's initial states."""
    concepts: tuple[dict[str, frozenset[str]], ...]
    """Each device's states → the concepts each state is (closed under superclasses)."""
    leaves: dict[tuple[str, str, int], dict[str, frozenset[str]]]
    """(process, role, device) → start state → states playing the role leaves the device in."""
    recovers: dict[tuple[str, str, int], frozenset[str]]
    tasks: tuple[TaskSpec, ...]
    bits: dict[str, int]
    """Each catalogue device's bit."""
    full: FullCheck

    def bit(self, device: str) -> int:
        """The bit of a catalogue device (0 when it is not in the catalogue)."""
        return self.bits.get(device, 0)


def abilities(catalogue: Sequence[DeviceDescription], tasks: Sequence[tuple[str, Task]],
              knowledge: Knowledge) -> Abilities:
    """Reason once over every catalogue device and task; compile the answers into :class:`Abilities`."""
    taxonomy, processes = knowledge.taxonomy, knowledge.processes
    devices = sorted({d.id: d for d in catalogue}.values(), key=lambda d: d.id)
    index = {d.id: n for n, d in enumerate(devices)}
    proc_atoms = [a for p in processes for a in process_facts(p)]
    dev_atoms = [a for d in devices for a in device_facts(d, taxonomy, processes)]
    task_atoms = [a for name, t in tasks for a in task_facts(t, name)]
    model = solver.solve(solver.ABILITIES, program(proc_atoms + dev_atoms + task_atoms))
    players: dict[PR, int] = defaultdict(int)
    for c in model[s.CanPlay]:
        players[(c.p, c.r)] |= 1 << index[c.d]
    bad = {(b.t, b.i) for b in model[s.BadValue]}
    return Abilities(
        devices=tuple(d.id for d in devices),
        costs=tuple(round(d.cost) for d in devices),
        processes=tuple(sorted((p.id, tuple(r.name for r in p.roles)) for p in processes)),
        players=dict(players),
        skills={(p.id, r.name): r.required_skill for p in processes for r in p.roles},
        first=_first_concepts(proc_atoms),
        initial=_initial(dev_atoms, index),
        concepts=_concepts(dev_atoms, index),
        leaves=_leaves(dev_atoms, index),
        recovers=_recovers(dev_atoms, index),
        tasks=tuple(_task(name, t, knowledge, bad, _refusing(devices, processes, taxonomy), devices)
                    for name, t in tasks),
        bits={d.id: 1 << n for n, d in enumerate(devices)},
        full=FullCheck(tuple(devices), type(knowledge)((), taxonomy, processes)),
    )


def _first_concepts(atoms: list[Atom]) -> dict[PR, str]:
    return {(a.p, a.r): a.c for a in atoms if isinstance(a, s.RegionState) and a.i == 1}


def _initial(atoms: list[Atom], index: dict[str, int]) -> tuple[frozenset[str], ...]:
    out: list[set[str]] = [set() for _ in index]
    for a in atoms:
        if isinstance(a, s.Initial):
            out[index[a.d]].add(a.x)
    return tuple(frozenset(x) for x in out)


def _concepts(atoms: list[Atom], index: dict[str, int]) -> tuple[dict[str, frozenset[str]], ...]:
    out: list[dict[str, set[str]]] = [defaultdict(set) for _ in index]
    for a in atoms:
        if isinstance(a, s.StateIs):
            out[index[a.d]][a.x].add(a.c)
    return tuple({x: frozenset(c) for x, c in d.items()} for d in out)


def _leaves(atoms: list[Atom], index: dict[str, int]) -> dict[tuple[str, str, int], dict[str, frozenset[str]]]:
    out: dict[tuple[str, str, int], dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
    for a in atoms:
        if isinstance(a, s.Leaves):
            out[(a.p, a.r, index[a.d])][a.x].add(a.y)
    return {k: {x: frozenset(y) for x, y in v.items()} for k, v in out.items()}


def _recovers(atoms: list[Atom], index: dict[str, int]) -> dict[tuple[str, str, int], frozenset[str]]:
    out: dict[tuple[str, str, int], set[str]] = defaultdict(set)
    for a in atoms:
        if isinstance(a, s.Recovers):
            out[(a.p, a.r, index[a.d])].add(a.y)
    return {k: frozenset(v) for k, v in out.items()}


def _refusing(devices: Sequence[DeviceDescription], processes: Sequence[ProcessDescription],
              taxonomy: Taxonomy) -> dict[tuple[str, str], int]:
    """(process, parameter) → the devices no command of which accepts the parameter's quantity (accepts.py)."""
    return {(p.id, par.name): sum(1 << n for n, d in enumerate(devices) if not accepts(d, par.quantity, taxonomy))
            for p in processes for par in p.parameters}


def _task(name: str, written: Task, knowledge: Knowledge, bad: set[tuple[str, int]],
          refusing: dict[tuple[str, str], int], devices: Sequence[DeviceDescription]) -> TaskSpec:
    task = normalised(written, knowledge.processes)[0]
    by_id = knowledge.processes_by_id
    steps = []
    for step in task.steps:
        p = by_id.get(step.command)
        roles = tuple((r.name, step.bind.get(r.name)) for r in p.roles) if p is not None else ()
        known = {r for r, _ in roles}
        unknown = tuple(sorted(r for r in step.bind if r not in known)) if p is not None else ()
        declared = {par.name: par for par in p.parameters} if p is not None else {}
        refusals = tuple((declared[n].role, refusing[(step.command, n)]) for n in sorted(step.params)
                         if n in declared)
        limits = _limits(step.params, declared, devices)
        beyond: dict[str, int] = defaultdict(int)
        for role, k, _ in limits:
            beyond[role] |= 1 << k
        steps.append(StepSpec(step.index, p.id if p is not None else None, roles, unknown,
                              (name, step.index) in bad, refusals, tuple(sorted(beyond.items())), limits))
    flow = task.loops or task.branches or any(step.links() for step in task.steps)
    return TaskSpec(name, tuple(steps), written if flow else None)


def _limits(params: Mapping[str, object], declared: dict[str, Parameter],
            devices: Sequence[DeviceDescription]) -> tuple[tuple[str, int, str], ...]:
    """Per value sent (given or the default) and catalogue device whose own limits refuse it: the role it goes to,
    the device's index and why (:func:`.contracts.refusal`)."""
    out = []
    for n, par in sorted(declared.items()):
        value = params.get(n, par.default)
        if value is None:
            continue
        for k, d in enumerate(devices):
            why = refusal(d, value, par, n in params)
            if why is not None:
                out.append((par.role, k, why))
    return tuple(out)
