"""Minimal-cost repairs of an implausible task (repair.lp), optimal first, then the next-best distinct ones.

The search is clingo's: one ``Control`` optimises (core-guided, ``usc``), and each next
repair is optimal once every repair containing an earlier one's edits is forbidden
(multi-shot, same ``Control``). With a catalogue, a first optimisation runs without it;
adding a device costs at least the cheapest device's price, so when the repairs found
without devices already cost no more than that, they are the answer and the larger
program with the catalogue is never grounded.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Step, Task
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from plugnproduce.reasoning.asp.facts import FactBook, fact_book, task_facts
from plugnproduce.reasoning.asp.results import Edit, Repair, RepairCosts
from plugnproduce.reasoning.asp.schema import edits
from plugnproduce.reasoning.asp.terms import Atom, Model, program, quote
from plugnproduce.reasoning.checks.contracts import normalised
from plugnproduce.reasoning.checks.offers import CELL, cell_program
from plugnproduce.reasoning.checks.plausibility import TASK, check
from plugnproduce.reasoning.checks.refusals import Refusals, refusal_facts, reset_reason

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

PER_GAP = 2
"""Default number of commands that may be inserted before each step."""


def _hundredths(x: float) -> int:
    return round(100 * x)


def horizon(task: Task, per_gap: int, max_inserts: int | None) -> list[Atom]:
    """The slots: ``per_gap`` insertion slots before each original step's home slot."""
    atoms: list[Atom] = [s.RepairScope(CELL, TASK)]
    slot = 0
    for step in task.steps:
        for j in range(1, per_gap + 1):
            slot += 1
            atoms += [s.Slot(slot), s.Gap(slot, step.index, j)]
        slot += 1
        atoms += [s.Slot(slot), s.Home(slot, step.index)]
    if max_inserts is not None:
        atoms.append(s.MaxInserts(max_inserts))
    return atoms


def cost_facts(costs: RepairCosts, processes: Sequence[ProcessDescription],
               catalogue: Sequence[DeviceDescription]) -> list[Atom]:
    """Edit costs in hundredths."""
    out: list[Atom] = [s.EditCost("insert", p.id, _hundredths(costs.insert + costs.insert_per_role * len(p.roles)))
                       for p in processes]
    out += [s.EditCost(k, "", _hundredths(getattr(costs, k))) for k in ("remove", "swap", "rebind", "reset")]
    out += [s.EditCost("add", d.id, add_cost(costs, d)) for d in catalogue]
    if not costs.add_device_per_price:
        out += [s.TiePrice(d.id, _hundredths(d.cost)) for d in catalogue]
    return out


def add_cost(costs: RepairCosts, device: DeviceDescription) -> int:
    """The cost of adding ``device`` to the cell, in hundredths."""
    return _hundredths(costs.add_device + costs.add_device_per_price * device.cost)


def forbid(model: Model) -> str:
    """An integrity constraint ruling out this repair's edits (and any repair containing them)."""
    lits = []
    for e in model[s.Edit]:
        if isinstance(e.e, edits.Insert):  # wherever in the same gap: inserting P before step I
            lits.append(f"inserted({e.e.i},{quote(e.e.p)})")
        else:
            lits.append(f"edit({edits.edit_text(e.e)})")
    return ":- " + ", ".join(sorted(set(lits))) + "." if lits else ":- #true."


def outcome(model: Model, task: Task) -> Hashable:
    """What a repair leads to: the commands, bindings and parameter values of the repaired task, the cell."""
    steps = repaired_task(model, task).steps
    added = sorted(e.e.a for e in model[s.Edit] if isinstance(e.e, edits.Add))
    commands = tuple((st.command, tuple(sorted(st.bind.items())), repr(sorted(st.params.items()))) for st in steps)
    return commands, tuple(added)


def task_program(task: Task, devices: Sequence[DeviceDescription], book: FactBook,
                 known: Refusals | None = None) -> str:
    """The facts of a task to repair: its values read in their parameters' units (``"40 %"`` is the number 40, as
    the check reads it; a value that cannot be read stays as written, to be reset), and which of ``devices`` (the
    cell's and the catalogue's) refuse which of them (:mod:`..checks.refusals`; ``known``: the answers so far)."""
    readable, _ = normalised(task, book.processes, keep_unreadable=True)
    return program(task_facts(readable, TASK)
                   + refusal_facts(readable, TASK, devices, book.knowledge, known))


def _optimise(book: FactBook, task: Task, cell: Cell, extra: Sequence[DeviceDescription], top: int,
              costs: RepairCosts, per_gap: int, max_inserts: int | None, known: Refusals) -> list[Model]:
    facts = (cell_program(book, cell, extra) + task_program(task, [*cell.devices, *extra], book, known)
             + program(horizon(task, per_gap, max_inserts))
             + program(cost_facts(costs, book.processes, extra))
             + program(s.Catalogue(d.id) for d in extra))
    return solver.optimise(solver.REPAIR, facts, top, forbid, lambda m: outcome(m, task))


def repair(
    task: Task,
    cell: Cell,
    knowledge: Knowledge,
    catalogue: Sequence[DeviceDescription] | None = None,
    top: int = 3,
    costs: RepairCosts | None = None,
    per_gap: int = PER_GAP,
    max_inserts: int | None = None,
) -> list[Repair]:
    """The ``top`` cheapest distinct repairs of ``task`` in ``cell`` (empty if it is plausible already)."""
    costs = costs or RepairCosts()
    if top < 1 or check(task, cell, knowledge).plausible:
        return []
    book = fact_book(knowledge)
    present = {d.id for d in cell.devices}
    extra = sorted({d.id: d for d in catalogue or () if d.id not in present}.values(), key=lambda d: d.id)
    known = Refusals(knowledge.taxonomy)
    models = _optimise(book, task, cell, (), top, costs, per_gap, max_inserts, known)
    cheapest_add = min((add_cost(costs, d) for d in extra), default=None)
    if cheapest_add is not None and (len(models) < top or models[-1].cost[0] > cheapest_add):
        models = _optimise(book, task, cell, extra, top, costs, per_gap, max_inserts, known)
    devices = {d.id: d for d in [*extra, *cell.devices]}
    return [read_repair(m, rank, task, book, devices, costs) for rank, m in enumerate(models, start=1)]


# ------------------------------------------------------------------ reading a model back


def repaired_runs(model: Model, task: Task) -> list[tuple[int, Step]]:
    """The repaired task's steps in order, each with the original step position it keeps (0 if inserted)."""
    plays: dict[int, dict[str, str]] = {}
    for p in model[s.Plays]:
        if p.explicit:
            plays.setdefault(p.s, {})[p.r] = p.d
    resets = {(e.e.i, e.e.n) for e in model[s.Edit] if isinstance(e.e, edits.Reset)}
    out: list[tuple[int, Step]] = []
    for run in sorted(model[s.Runs], key=lambda r: r.s):
        bind = dict(sorted(plays.get(run.s, {}).items()))
        index = len(out) + 1
        if run.i == 0:
            out.append((0, Step(index, run.p, bind, {})))
            continue
        old = task.steps[run.i - 1]
        params = {k: v for k, v in old.params.items() if (run.i, k) not in resets}
        out.append((run.i, Step(index, run.p, bind, params, old.line, dict(old.param_lines), old.name)))
    return out


def repaired_task(model: Model, task: Task) -> Task:
    """The task the model's edits produce, flat; ``repeat`` kept when every round was repaired alike (loops and
    branches are lifted onto the written task afterwards, :mod:`plugnproduce.reasoning.repairs.lifting`)."""
    steps = [st for _, st in repaired_runs(model, task)]
    kept = len(steps) == len(task.steps)  # a loop's or branch's steps kept in place: still the loop, the branch
    return Task(task.name, tuple(steps), task.file, task.description, folded_repeat(steps, task.repeat),
                task.loops if kept else (), task.branches if kept else ())


def folded_repeat(steps: list[Step], most: int) -> int:
    """The largest ``repeat`` (at most ``most``) such that the steps are that many equal rounds."""
    for r in range(most, 1, -1):
        n = len(steps) // r
        shifted = zip(steps, steps[n:], strict=False)
        if n * r == len(steps) and all((a.command, a.bind, a.params) == (b.command, b.bind, b.params)
                                       for a, b in shifted):
            return r
    return 1


def read_repair(model: Model, rank: int, task: Task, book: FactBook, devices: dict[str, DeviceDescription],
                costs: RepairCosts) -> Repair:
    """A model of repair.lp as a :class:`Repair`."""
    reader = _EditReader(task, book, devices, costs, lambda i: bound_at(model, i))
    read = sorted((reader.read(e.e) for e in model[s.Edit]), key=lambda e: (e.step or 0, e.kind, e.text))
    added = tuple(sorted(e.device for e in read if e.kind == "add" and e.device))
    return Repair(rank, model.cost[0] / 100 if model.cost else 0.0, tuple(read),
                  repaired_task(model, task), added, tuple(i for i, _ in repaired_runs(model, task)))


def bound_at(model: Model, i: int) -> dict[str, str]:
    """The devices the repaired task binds to the roles of original step ``i`` (by role)."""
    slots = {r.s for r in model[s.Runs] if r.i == i}
    return {p.r: p.d for p in model[s.Plays] if p.s in slots}


class _EditReader:
    """Turns the edits of a model into :class:`Edit` objects with sentences and costs; ``bound`` tells the devices the
    repaired task binds to an original step's roles (to say which device's limit a reset value broke)."""

    def __init__(self, task: Task, book: FactBook, devices: dict[str, DeviceDescription], costs: RepairCosts,
                 bound: Callable[[int], dict[str, str]] | None = None):
        self.task, self.book, self.devices, self.costs = task, book, devices, costs
        self.bound = bound
        self._readable: list[Task] = []  # shared with the readers made by with_bound

    def with_bound(self, bound: Callable[[int], dict[str, str]]) -> _EditReader:
        """This reader with other devices bound to the steps' roles (the task read in its units is shared)."""
        reader = _EditReader(self.task, self.book, self.devices, self.costs, bound)
        reader._readable = self._readable
        return reader

    @property
    def readable(self) -> Task:
        """The task with its values read in their parameters' units, read once (a long task has many resets)."""
        if not self._readable:
            self._readable.append(normalised(self.task, self.book.processes)[0])
        return self._readable[0]

    def read(self, term: edits.EditTerm) -> Edit:
        """The edit with its sentence and cost."""
        match term:
            case edits.Insert(i, j, p):
                return self._insert(i, j, p)
            case edits.Remove(i):
                return self._remove(i)
            case edits.Swap(i):
                return self._swap(i)
            case edits.Rebind(i, r, d):
                return self._rebind(i, r, d)
            case edits.Bind(i, r, d):
                return self._bind(i, r, d)
            case edits.Unbind(i, r):
                return self._unbind(i, r)
            case edits.Reset(i, n):
                return self._reset(i, n)
            case edits.Add(a):
                return self._add(a)

    def cmd(self, i: int) -> str:
        """The command of original step ``i``."""
        return self.task.steps[i - 1].command

    def _insert(self, i: int, _j: int, p: str) -> Edit:
        cost = self.costs.insert + self.costs.insert_per_role * len(self.book.process(p).roles)
        return Edit("insert", f"insert {p} before step {i} ({self.cmd(i)})", cost, i, p)

    def _remove(self, i: int) -> Edit:
        return Edit("remove", f"remove step {i} ({self.cmd(i)})", self.costs.remove, i, self.cmd(i))

    def _swap(self, i: int) -> Edit:
        text = f"swap step {i} ({self.cmd(i)}) with step {i + 1} ({self.cmd(i + 1)})"
        return Edit("swap", text, self.costs.swap, i, self.cmd(i))

    def _rebind(self, i: int, r: str, d: str) -> Edit:
        old = self.task.steps[i - 1].bind.get(r)
        text = f"step {i} ({self.cmd(i)}): bind role '{r}' to device '{d}' instead of '{old}'"
        return Edit("rebind", text, self.costs.rebind, i, self.cmd(i), r, d)

    def _bind(self, i: int, r: str, d: str) -> Edit:
        text = f"step {i} ({self.cmd(i)}): bind role '{r}' to device '{d}' (several devices fit)"
        return Edit("bind", text, self.costs.rebind, i, self.cmd(i), r, d)

    def _unbind(self, i: int, r: str) -> Edit:
        text = f"step {i} ({self.cmd(i)}): drop the binding of '{r}', which is no role of {self.cmd(i)}"
        return Edit("unbind", text, self.costs.rebind, i, self.cmd(i), r)

    def _reset(self, i: int, n: str) -> Edit:
        par = next((x for x in self.book.process(self.cmd(i)).parameters if x.name == n), None)
        what = f"reset parameter {n} to its default {par.default}" if par else f"drop parameter {n} (not declared)"
        if par is not None and self.bound is not None:
            device = self.devices.get(self.bound(i).get(par.role, ""))
            why = reset_reason(device, self.readable.steps[i - 1].params.get(n), par, self.book.taxonomy)
            what += f" ({why})" if why else ""
        return Edit("reset", f"step {i} ({self.cmd(i)}): {what}", self.costs.reset, i, self.cmd(i), parameter=n)

    def _add(self, a: str) -> Edit:
        dev = self.devices.get(a)
        label = f" ({dev.label}, price {dev.cost:g})" if dev else ""
        price = self.costs.add_device + self.costs.add_device_per_price * (dev.cost if dev else 0.0)
        return Edit("add", f"add device '{a}'{label} to the cell", round(price, 4), device=a)
