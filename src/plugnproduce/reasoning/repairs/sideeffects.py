"""Side effects of repairs: what else a repair changes besides making the task plausible, and the ranking that
puts repairs losing a held part (or moving a device a later step relies on) below those that do not.

A repair is checked again (it must be plausible); then its steps are followed device by device. A gripping
device holds a part after a pick process (a process of class ``PickProcess``) leaves it closed, or while it is in
a state of concept ``HoldingPart``; a step that leaves it open releases the part — placed when the step is a place
process, dropped where the robot stands otherwise. The repair solver is not changed: this works on its results.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Step, Task, Where
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp.derivation import Node, asp
from plugnproduce.reasoning.asp.results import CheckResult, Repair
from plugnproduce.reasoning.checks.offers import CELL
from plugnproduce.reasoning.checks.plausibility import TASK, check
from plugnproduce.reasoning.checks.recheck import Moves, recheck

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

SEVERITY = {"drops_part": 2, "moves_device": 1, "ends_holding": 1, "default_values": 0}
"""How much each kind of side effect weighs when repairs are ranked (0: worth knowing, harmless)."""


@dataclass(frozen=True)
class SideEffect:
    """One thing a repair changes besides what it fixes."""

    kind: str
    """``drops_part``, ``moves_device``, ``ends_holding`` or ``default_values``."""
    text: str
    step: int
    """The step of the repaired task it happens at."""
    device: str | None = None
    evidence: tuple[Node, ...] = ()
    """What the side effect rests on: the processes' classes and the chart states (a derivation's nodes)."""

    @property
    def severity(self) -> int:
        """How much it weighs in the ranking (:data:`SEVERITY`)."""
        return SEVERITY[self.kind]

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"kind": self.kind, "text": self.text, "step": self.step, "device": self.device,
                "severity": self.severity, "evidence": [n.to_json() for n in self.evidence]}


@dataclass(frozen=True)
class AssessedRepair:
    """A repair with its side effects, its rank after them, and whether the reasoner confirms it."""

    rank: int
    repair: Repair
    side_effects: tuple[SideEffect, ...]
    confirmed: bool
    """Checking the repaired task again finds it plausible (:func:`assess` proposes only such repairs)."""
    checked: CheckResult | None = dataclasses.field(default=None, compare=False, repr=False)
    """That check of the repaired task (in the cell with the devices the repair adds), for what follows from it
    (its estimated cycle time), so that a long task is not checked once more."""

    @property
    def severity(self) -> int:
        """The weight of its worst side effect (0 when it has none that matter)."""
        return max((e.severity for e in self.side_effects), default=0)

    @property
    def derivation(self) -> Node:
        """Why this repair is offered: the repaired task checked again, and each side effect with its evidence."""
        edits = "; ".join(e.text for e in self.repair.edits)
        checked = (asp("resolve.lp", "plausible", "checking the repaired task again finds no problem at any step",
                       {"C": CELL, "T": TASK}),) if self.confirmed else ()
        effects = tuple(Node("task", e.text, e.kind, children=e.evidence) for e in self.side_effects)
        verdict = "makes the task plausible" if self.confirmed else "does not make the task plausible"
        return Node("answer", f"repair {self.rank} ({edits}) {verdict}", children=checked + effects)

    def to_json(self) -> dict[str, object]:
        """The repair's JSON with its rank after side effects, the solver's rank, the side effects and the
        derivation."""
        return {**self.repair.to_json(), "rank": self.rank, "solver_rank": self.repair.rank,
                "confirmed": self.confirmed, "side_effects": [e.to_json() for e in self.side_effects],
                "derivation": self.derivation.to_json()}


@dataclass(frozen=True)
class _Cell:
    knowledge: Knowledge
    _answers: dict[tuple[str, str | None, str], bool] = dataclasses.field(default_factory=dict, compare=False)
    """What :meth:`is_a` and :meth:`process_is` answered (a long task asks the same at every step)."""

    @property
    def taxonomy(self) -> Taxonomy:
        return self.knowledge.taxonomy

    @property
    def processes(self) -> Mapping[str, ProcessDescription]:
        return self.knowledge.processes_by_id

    def is_a(self, iri: str | None, local: str) -> bool:
        key = ("concept", iri, local)
        if key not in self._answers:
            self._answers[key] = iri is not None and self.taxonomy.is_a(iri, PNP_IRI + local)
        return self._answers[key]

    def process_is(self, command: str, local: str) -> bool:
        key = ("process", command, local)
        if key not in self._answers:
            proc = self.processes.get(command)
            self._answers[key] = proc is not None and any(self.is_a(c, local) for c in proc.classes)
        return self._answers[key]

    def moves(self, command: str, role: str) -> bool:
        proc = self.processes.get(command)
        return proc is not None and any(self.is_a(rs.concept, "Moving") for rs in proc.role(role).region)

    def starts_moving(self, command: str, role: str) -> bool:
        proc = self.processes.get(command)
        region = proc.role(role).region if proc else ()
        return len(region) > 1 and self.is_a(region[1].concept, "Moving")


def _sig(step: Step) -> tuple[object, ...]:
    return (step.command, tuple(sorted(step.bind.items())), tuple(sorted((k, str(v)) for k, v in step.params.items())))


def new_steps(original: Task, repaired: Task, origins: Sequence[int] = ()) -> set[int]:
    """The (1-based) steps of ``repaired`` that are not original steps kept in their order (inserted or moved):
    a longest common subsequence, matched from the end so an inserted step is the one before the kept ones.

    With ``origins`` (the original position each repaired step keeps, 0 if inserted: :attr:`Repair.origins`) a
    step is matched by where it came from, so a step rebound or with a value reset is still the original step."""
    if len(origins) == len(repaired.steps) and origins:
        return _unmatched(list(range(1, len(original.steps) + 1)), list(origins))
    return _unmatched([_sig(s) for s in original.steps], [_sig(s) for s in repaired.steps])


def _unmatched(a: Sequence[Hashable], b: Sequence[Hashable]) -> set[int]:
    """The (1-based) positions of ``b`` outside a longest common subsequence with ``a``, matched from the end."""
    lcs = _lcs_rows(a, b)
    fresh, i, j = set(), len(a), len(b)
    while j > 0:
        if i > 0 and a[i - 1] == b[j - 1] and lcs(i, j) == lcs(i - 1, j - 1) + 1:
            i, j = i - 1, j - 1
        elif i > 0 and lcs(i - 1, j) == lcs(i, j):
            i -= 1
        else:
            fresh.add(j)
            j -= 1
    return fresh


def _lcs_rows(a: Sequence[Hashable], b: Sequence[Hashable]) -> Callable[[int, int], int]:
    """The length of the longest common subsequence of ``a[:i]`` and ``b[:j]``, for any ``i`` and ``j``.

    Bit-parallel (Hyyrö's row recurrence): row ``i`` is one integer whose zero bits below ``j`` count that
    length, so the table of a 10,000-step task is 10,000 integer operations rather than 10^8 cells."""
    full = (1 << len(b)) - 1
    matches: dict[Hashable, int] = {}
    for j, x in enumerate(b):
        matches[x] = matches.get(x, 0) | 1 << j
    rows = [full]
    for x in a:
        v = rows[-1]
        u = v & matches.get(x, 0)
        rows.append(((v + u) | (v - u)) & full)

    def lcs(i: int, j: int) -> int:
        return j - (rows[i] & ((1 << j) - 1)).bit_count()

    return lcs


def _concept(cell: Cell, d: str, x: str | None) -> str | None:
    dev = next((v for v in cell.devices if v.id == d), None)
    return next((st.concept for st in dev.states if st.id == x), None) if dev and x else None


def _after(result: CheckResult, i: int) -> dict[str, str]:
    return result.steps[i].states if i < len(result.steps) else result.final_states


def _mover(k: _Cell, result: CheckResult, i: int, cell: Cell) -> str:
    step = result.steps[i - 1]
    movers = [d for r, d in step.bindings.items() if k.moves(step.command, r)]
    movers += [d for d, x in step.states.items() if k.is_a(_concept(cell, d, x), "MotionState")]
    if not movers:
        return "where it is"
    d = movers[0]
    x = step.states.get(d)
    return f"where device '{d}' stands (state '{x}', {k.taxonomy.label(_concept(cell, d, x) or '')})"


def _state_node(cell: Cell, d: str, x: str | None, text: str) -> Node:
    dev = next(v for v in cell.devices if v.id == d)
    line = next((st.line for st in dev.states if st.id == x), None)
    return Node("chart", text, f"{dev.chart_file} state {x}", Where(dev.chart_file, line))


def _drop_evidence(k: _Cell, result: CheckResult, cell: Cell, j: int, i: int, d: str) -> tuple[Node, ...]:
    """Why step ``i`` drops the part step ``j`` picked: ``j`` is a pick process that left ``d`` closed, ``i``
    leaves it open and is no place process."""
    picker, opener = result.steps[j - 1].command, result.steps[i - 1].command
    held, opened = _after(result, j).get(d), _after(result, i).get(d)
    label = k.taxonomy.label
    out = []
    if picker in k.processes:
        out.append(Node("owl", f"{picker} is a '{label(PNP_IRI + 'PickProcess')}': it leaves a part in the gripper",
                        f"{picker} : PickProcess", k.processes[picker].where))
    out.append(_state_node(cell, d, held, f"step {j} ({picker}) left device '{d}' in state '{held}' "
                                          f"('{label(_concept(cell, d, held) or '')}')"))
    out.append(_state_node(cell, d, opened, f"step {i} ({opener}) leaves device '{d}' in state '{opened}' "
                                            f"('{label(_concept(cell, d, opened) or '')}')"))
    if opener in k.processes:
        out.append(Node("owl", f"{opener} is not a '{label(PNP_IRI + 'PlaceProcess')}'", f"{opener} ⋢ PlaceProcess",
                        k.processes[opener].where, True))
    return tuple(out)


def _holding(k: _Cell, result: CheckResult, cell: Cell, fresh: set[int], task: Task,
             original: Task, origins: Sequence[int]) -> list[SideEffect]:
    out: list[SideEffect] = []
    held: dict[str, int] = {}
    concepts: dict[tuple[str, str | None], str | None] = {}  # _concept, indexed: the first device and state
    for dev in reversed(cell.devices):
        concepts.update({(dev.id, st.id): st.concept for st in reversed(dev.states)})
    kinds: dict[tuple[str, str | None], tuple[bool, bool, bool]] = {}  # a state left in: open, holding, closed
    for i, step in enumerate(result.steps, start=1):
        left = _after(result, i)
        for d in step.bindings.values():
            kind = kinds.get(key := (d, left.get(d)))
            if kind is None:
                after = concepts.get(key)
                kind = kinds[key] = (k.is_a(after, "Open"), k.is_a(after, "HoldingPart"), k.is_a(after, "Closed"))
            opened, holding, closed = kind
            if d in held and opened and not k.process_is(step.command, "PlaceProcess"):
                picker = f"step {held[d]} ({result.steps[held[d] - 1].command})"
                out.append(SideEffect("drops_part", f"step {i} ({step.command}) opens device '{d}', which holds the "
                                                    f"part {picker} picked: the part would be released "
                                                    f"{_mover(k, result, i, cell)}, not placed", i, d,
                                      _drop_evidence(k, result, cell, held[d], i, d)))
            if opened:
                held.pop(d, None)
            elif holding or (closed and k.process_is(step.command, "PickProcess")):
                held[d] = i
        if i in fresh:
            if len(origins) == len(task.steps) and origins:
                inserted = origins[i - 1] == 0
            else:
                sig = _sig(task.steps[i - 1])
                inserted = sum(_sig(s) == sig for s in task.steps) > sum(_sig(s) == sig for s in original.steps)
            out += _moves(k, result, i, task, inserted)
    return out


def _moves(k: _Cell, result: CheckResult, i: int, task: Task, inserted: bool) -> list[SideEffect]:
    out: list[SideEffect] = []
    step = result.steps[i - 1]
    for role, d in step.bindings.items():
        if not k.moves(step.command, role):
            continue
        nxt = next(((j, s) for j, s in enumerate(result.steps[i:], start=i + 1) if d in s.bindings.values()), None)
        if nxt is None:
            continue
        j, later = nxt
        role_there = next(r for r, v in later.bindings.items() if v == d)
        if not k.starts_moving(later.command, role_there):
            out.append(SideEffect("moves_device", f"step {i} ({step.command}) moves device '{d}', and step {j} "
                                                  f"({later.command}) relies on where it was left", i, d))
    defaults = [p for p in k.processes[step.command].parameters if p.name not in task.steps[i - 1].params] \
        if inserted and step.command in k.processes else []
    if defaults:
        values = ", ".join(f"{p.name} = {p.default}" for p in defaults[:4])
        out.append(SideEffect("default_values", f"step {i} ({step.command}) runs with default values: {values}", i))
    return out


def side_effects(original: Task, repaired: Task, result: CheckResult, cell: Cell, knowledge: Knowledge,
                 before: CheckResult, origins: Sequence[int] = ()) -> list[SideEffect]:
    """What the repaired task changes besides being plausible: parts dropped, devices moved, a part still held
    at the end that the original task released, default values of inserted steps (``origins``: see
    :func:`new_steps`)."""
    k = _Cell(knowledge)
    fresh = new_steps(original, repaired, origins)
    out = _holding(k, result, cell, fresh, repaired, original, origins)
    ends = [d for d, x in result.final_states.items() if k.is_a(_concept(cell, d, x), "Closed")
            and not k.is_a(_concept(cell, d, before.final_states.get(d)), "Closed")]
    if ends and any(k.process_is(s.command, "PickProcess") for s in repaired.steps):
        out += [SideEffect("ends_holding", f"the task ends with device '{d}' closed, holding the last part it "
                                           f"picked (the original task ends with it open)", len(result.steps), d)
                for d in ends]
    return out


def assess(repairs: Sequence[Repair], task: Task, cell: Cell, knowledge: Knowledge,
           catalogue: Sequence[DeviceDescription] = (), before: CheckResult | None = None) -> list[AssessedRepair]:
    """Each repair that checking it again (in the cell with the devices it adds from ``catalogue``, with their own
    contracts and limits) confirms, with its side effects: ranked by its worst side effect, then by cost, then by
    the solver's order. A repair the check does not confirm is no repair: it is left out. ``before``: the check
    of ``task`` in ``cell``, when the caller has it already."""
    before = before if before is not None else check(task, cell, knowledge)
    moves = Moves(cell, knowledge, task, before)  # a long task's steps the repair left alone are not checked again
    out = []
    for r in repairs:
        added = tuple(d for d in catalogue if d.id in r.added_devices)
        the_cell = dataclasses.replace(cell, devices=cell.devices + added)
        result = (None if added else recheck(r.task, moves)) or check(r.task, the_cell, knowledge)
        if not result.plausible:
            continue
        effects = side_effects(task, r.task, result, the_cell, knowledge, before, r.origins)
        out.append(AssessedRepair(0, r, tuple(effects), True, result))
    return [dataclasses.replace(a, rank=n) for n, a in enumerate(sorted(out, key=ranking), start=1)]


def ranking(repair: AssessedRepair) -> tuple[int, float, int]:
    """The order repairs are proposed in: by their worst side effect (:data:`SEVERITY`: none or default values
    first, a dropped part last), then by cost, cheapest first, then by the solver's order."""
    return (repair.severity, repair.repair.cost, repair.repair.rank)
