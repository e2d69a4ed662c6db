"""Repair of a long task window by window (window.lp with repair.lp): cost linear in the task's length.

The plausibility check gives, for every step of the task as written, the chart state of every
device when the step starts (a broken step leaves its devices where it would have left them,
``recovers/4``); a value the device bound to a step refuses by its own limits is a problem of that
step too (the check finds it outside the encodings, repair.lp resets it). Each problem spans the
steps from the one that last used its device to the step that fails; a *window* is such a span
widened by ``margin`` unbroken steps on each side, overlapping windows merged. Each window is
repaired on its own by repair.lp, with

- the devices *entering* the window in the states the check found there (the steps before it
  are unbroken, or earlier windows left every device a later step uses in its original state), and
- every device a step after the window uses *leaving* it in the state the check found after
  it (window.lp's ``exit_state/2``), so the unbroken steps that follow run exactly as written.

Why the combination is optimal. Write the task as ``G0 W1 G1 ... Wm Gm``: windows ``Wk`` and the
unbroken stretches ``Gk`` between them. A device changes state only when a step uses it, so the
state a step finds a device in is the one its previous use left; every problem's span reaches back
to that use, so no problem depends on a step of a stretch.

(1) *Feasible.* By the exit condition every ``Gk`` starts in the states the check found, in which
it was plausible; so the stitched task is plausible (and :func:`windowed_repair`'s tests check it).

(2) *Optimal among repairs that leave the stretches as written.* Edits are priced per edit, not by
position, so such a repair ``R`` costs the sum of the edits it makes in each window. Restricted to
``Wk``, ``R`` enters in the states ``G(k-1)`` leaves and must leave every device a later step uses
as ``Gk`` expects it (``Gk``'s steps are unchanged and each device's state changes only when used):
a feasible repair of ``Wk`` alone, costing at least ``Wk``'s optimum. So ``cost(R) >=`` the sum of
the window optima, which is what the stitched repair costs.

(3) *Editing a stretch gains nothing* (an argument, not a proof): its steps are plausible, so an
edit there only changes the states the next windows enter in; an insertion costs the same in the
gap before a window's first step, where it has the same effect on the devices the window uses, and
removing, swapping or rebinding plausible steps costs (with the default costs) at least as much as
the cheapest insertion, which has the same effect next to the window.
``tests/reasoning/test_windows.py`` compares the windowed and the whole-task optimum on random
tasks (property test); ``bench/bench_repair.py`` compares them on 100- and 1,000-step tasks.

Where the costs break (3) (removing, swapping or rebinding a step cheaper than the cheapest
insertion: :func:`edits_stay_local`), wider windows can find cheaper repairs, and random tasks show
they do. Then the windows are solved with margin ``m`` and again with ``2m``, and the answer is
taken when both cost the same, else the margins keep doubling: a check, not a proof. Margins also
double when a window has no repair within its borders. At worst one window covers the task and
this is the whole-task repair of :mod:`.repairs`.

Devices from a catalogue are shared by all windows (one purchase may fix several), so their
windows are not independent: each window is first solved with every catalogue device priced one
hundredth; the device sets they would buy (each, and all together) are then tried as fixed
additions to the cell, priced in full once, and the cheapest total (or none bought) wins. This is
optimal over those purchases, not proven optimal over every subset of the catalogue.
The ``top`` best repairs combine the windows' own best repairs (k-best sums, distinct because
the windows are); a window's third and later repairs are solved only when the sums reach them.
"""

from __future__ import annotations

import heapq
from collections import defaultdict
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Step, Task
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from plugnproduce.reasoning.asp.facts import FactBook, fact_book, task_facts
from plugnproduce.reasoning.asp.results import Repair, RepairCosts
from plugnproduce.reasoning.asp.schema import edits
from plugnproduce.reasoning.asp.terms import Model, program
from plugnproduce.reasoning.checks.contracts import normalised
from plugnproduce.reasoning.checks.offers import CELL, cell_program
from plugnproduce.reasoning.checks.plausibility import TASK
from plugnproduce.reasoning.checks.refusals import Refusals, refusal_facts
from plugnproduce.reasoning.repairs import lifting, repairs

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

WHOLE_UP_TO = 40
"""Tasks of at most this many steps are repaired whole (:func:`.repairs.repair`): fast enough, and
their next-best repairs then follow the whole-task order exactly."""

MARGIN = 2
"""Unbroken steps first added on each side of a problem's span."""

FIRST = 2
"""Repairs of each window solved at once; the next ones only for a window whose second is in a combination."""


@dataclass(frozen=True, order=True)
class Window:
    """Original steps ``first`` to ``last`` (1-based, inclusive)."""

    first: int
    last: int


@dataclass(frozen=True)
class _Part:
    """One repair of one window: its cost (hundredths), edits (original step numbers), steps."""

    window: Window
    cost: int
    edits: tuple[edits.EditTerm, ...]
    steps: tuple[Step, ...]
    origins: tuple[int, ...] = ()
    """The original (whole-task) step position each of :attr:`steps` keeps, 0 if inserted."""
    reset_bound: tuple[tuple[int, tuple[tuple[str, str], ...]], ...] = ()
    """For each original step with a value reset: the devices the repair binds to its roles (to say which
    device's limit the value broke)."""


class _Parts:
    """A window's repairs, cheapest first: its best two solved at once, the rest only when :func:`k_best` reaches
    them (the third of a window is wanted only when its second is in a combination already)."""

    def __init__(self, first: list[_Part], rest: Callable[[], list[_Part]] | None):
        self.parts, self._rest = first, rest

    def has(self, i: int) -> bool:
        """Whether the window has an ``i``-th repair (0-based), solving for the rest the first time it is asked."""
        if i >= len(self.parts) and self._rest is not None:
            self.parts, self._rest = self._rest(), None
        return i < len(self.parts)

    def __getitem__(self, i: int) -> _Part:
        return self.parts[i]


def k_best(options: Sequence[_Parts], k: int) -> list[tuple[_Part, ...]]:
    """The ``k`` cheapest ways to pick one part per window (each window's parts sorted by cost)."""
    def total(ix: tuple[int, ...]) -> int:
        return sum(options[w][i].cost for w, i in enumerate(ix))

    first = (0,) * len(options)
    heap, seen = [(total(first), first)], {first}
    out: list[tuple[_Part, ...]] = []
    while heap and len(out) < k:
        _, ix = heapq.heappop(heap)
        out.append(tuple(options[w][i] for w, i in enumerate(ix)))
        for w in range(len(ix)):
            nxt = ix[:w] + (ix[w] + 1,) + ix[w + 1:]
            if nxt not in seen and options[w].has(nxt[w]):
                seen.add(nxt)
                heapq.heappush(heap, (total(nxt), nxt))
    return out


class _Chain:
    """The task as checked (check.lp): device states before each step, its problems, each device's uses."""

    def __init__(self, task: Task, model: Model, refused: Iterable[s.ValueRefused] = ()):
        self.task, self.n = task, len(task.steps)
        self.at: dict[int, dict[str, str]] = defaultdict(dict)
        for a in model[s.At]:
            self.at[a.i][a.d] = a.x
        users: dict[int, set[str]] = defaultdict(set)
        for b in model[s.Bound]:
            users[b.i].add(b.d)
        at_device: list[s.WrongState | s.Stuck] = [*model[s.WrongState], *model[s.Stuck]]
        at_step: list[s.NoDevice | s.Ambiguous | s.Absent | s.CannotPlay | s.UnknownRole | s.UnknownCommand
                      | s.BadType | s.TooLow | s.TooHigh | s.UnknownParam] = [
            *model[s.NoDevice], *model[s.Ambiguous], *model[s.Absent], *model[s.CannotPlay], *model[s.UnknownRole],
            *model[s.UnknownCommand], *model[s.BadType], *model[s.TooLow], *model[s.TooHigh], *model[s.UnknownParam]]
        # a value the device bound to the step refuses by its own limits: found by the check outside the encodings
        beyond = {a.i for a in refused if a.d in users[a.i]}
        self.plausible = bool(model[s.Plausible]) and not beyond
        self.problems: list[tuple[int, str | None]] = [(a.i, a.d) for a in at_device] + [
            (i, None) for i in [*(a.i for a in at_step), *beyond]]
        self.last_use: dict[str, int] = {}
        self.used_before: dict[tuple[int, str], int] = {}
        for i in sorted(users):
            for d in users[i]:
                if d in self.last_use:
                    self.used_before[(i, d)] = self.last_use[d]
                self.last_use[d] = i

    def spans(self) -> list[Window]:
        """Per problem: from the step that last used its device (if any) to the failing step."""
        out = []
        for step, device in self.problems:
            first = self.used_before.get((step, device), step) if device else step
            out.append(Window(max(1, min(first, step)), min(self.n, max(1, step))))
        return out

    def states(self, i: int) -> dict[str, str]:
        """Every device's state before original step ``i`` (``n + 1``: after the task)."""
        return dict(self.at[i])  # {} where no device has a state (each lost where it got stuck: no recovers/4)

    def exits(self, w: Window) -> dict[str, str]:
        """The states the steps after ``w`` expect: of each device one of them uses."""
        return {d: x for d, x in self.states(w.last + 1).items() if self.last_use.get(d, 0) > w.last}


def edits_stay_local(costs: RepairCosts, processes: Sequence[ProcessDescription]) -> bool:
    """Whether editing a plausible step costs at least the cheapest insertion (part 3 of the argument above)."""
    cheapest = min((costs.insert + costs.insert_per_role * len(p.roles) for p in processes), default=0.0)
    return min(costs.remove, costs.swap, costs.rebind) >= cheapest


def windows(spans: Iterable[Window], n: int, margin: int) -> list[Window]:
    """The spans widened by ``margin`` steps on each side (within 1..n), overlapping or touching ones merged."""
    out: list[Window] = []
    for w in sorted(Window(max(1, x.first - margin), min(n, x.last + margin)) for x in spans):
        if out and w.first <= out[-1].last + 1:
            out[-1] = Window(out[-1].first, max(out[-1].last, w.last))
        else:
            out.append(w)
    return out


def repair(
    task: Task,
    cell: Cell,
    knowledge: Knowledge,
    catalogue: Sequence[DeviceDescription] | None = None,
    top: int = 3,
    costs: RepairCosts | None = None,
    per_gap: int = repairs.PER_GAP,
    max_inserts: int | None = None,
) -> list[Repair]:
    """The ``top`` cheapest distinct repairs of ``task`` in ``cell``: whole if short, else window by window;
    each lifted onto the written task, its loops and branches kept where that is plausible (:mod:`lifting`)."""
    if len(task.steps) <= WHOLE_UP_TO or max_inserts is not None:
        found = repairs.repair(task, cell, knowledge, catalogue, top, costs, per_gap, max_inserts)
    else:
        found = windowed_repair(task, cell, knowledge, catalogue, top, costs, per_gap)
    return lifting.lifted(found, task, cell, knowledge, catalogue or ())


def windowed_repair(
    task: Task,
    cell: Cell,
    knowledge: Knowledge,
    catalogue: Sequence[DeviceDescription] | None = None,
    top: int = 3,
    costs: RepairCosts | None = None,
    per_gap: int = repairs.PER_GAP,
    margin: int = MARGIN,
) -> list[Repair]:
    """The ``top`` cheapest distinct repairs, each window repaired on its own (see the module's docstring).

    ``margin``: unbroken steps first added on each side of a problem (doubled until doubling it
    changes no cost)."""
    costs = costs or RepairCosts()
    book = fact_book(knowledge)
    readable, _ = normalised(task, knowledge.processes, keep_unreadable=True)  # "40 %" is 40, as the check reads it
    facts = cell_program(book, cell) + program(task_facts(readable, TASK)) + program([s.Check(CELL, TASK)])
    refused = [a for a in refusal_facts(readable, TASK, cell.devices, knowledge) if isinstance(a, s.ValueRefused)]
    chain = _Chain(task, solver.solve(solver.CHECK, facts), refused)  # the check's own model of this task
    if top < 1 or chain.plausible:  # plausible to the encodings: whatever else check() finds, repair.lp cannot fix
        return repairs.repair(task, cell, knowledge, catalogue, top, costs, per_gap) if top >= 1 else []
    present = {d.id for d in cell.devices}
    extra = sorted({d.id: d for d in catalogue or () if d.id not in present}.values(), key=lambda d: d.id)
    narrower: list[Repair] | None = None
    memo: dict[Hashable, list[Model]] = {}
    local = edits_stay_local(costs, knowledge.processes)
    while True:
        wins = windows(chain.spans(), chain.n, margin)
        if wins == [Window(1, chain.n)]:
            return repairs.repair(task, cell, knowledge, catalogue, top, costs, per_gap)
        found = _Solver(book, chain, cell, costs, per_gap, top, memo).best(wins, extra)
        if found is not None and (local or (narrower is not None
                                            and [r.cost for r in found] == [r.cost for r in narrower])):
            return found
        narrower = found
        margin = 2 * margin or 1


class _Solver:
    """Solves the windows of one task in one cell and combines their repairs."""

    def __init__(self, book: FactBook, chain: _Chain, cell: Cell, costs: RepairCosts, per_gap: int, top: int,
                 memo: dict[Hashable, list[Model]]):
        self.book, self.chain, self.cell, self.costs, self.per_gap, self.top = book, chain, cell, costs, per_gap, top
        self.memo = memo
        self.known = Refusals(book.taxonomy)

    def best(self, wins: list[Window], extra: list[DeviceDescription]) -> list[Repair] | None:
        """The top repairs (None when some window has no repair within its borders)."""
        found = self.combined(wins, ())
        cheapest = min((repairs.add_cost(self.costs, d) for d in extra), default=None)
        if cheapest is not None and (len(found) < self.top or found[-1][0] > cheapest):
            sets, free = self.purchases(wins, extra)
            if len(found) < self.top or found[-1][0] > cheapest + free:  # else no purchase can pay for itself
                for added in sets:
                    found += self.combined(wins, added)
                found.sort(key=lambda c: c[0])
        if not found:
            return None
        devices = {d.id: d for d in [*extra, *self.cell.devices]}
        reader = repairs._EditReader(self.chain.task, self.book, devices, self.costs)
        return [self.read(rank, c, reader) for rank, c in enumerate(found[:self.top], start=1)]

    def purchases(self, wins: list[Window], extra: list[DeviceDescription]
                  ) -> tuple[list[tuple[DeviceDescription, ...]], int]:
        """Device sets worth trying: what each window would buy were devices (nearly) free, and all together;
        and a lower bound on the cost of the edits of any repair that buys (hundredths).

        A purchase too dear for one window may pay for itself over several, so each window is asked
        with every device priced one hundredth; each set is then priced in full, once, by :meth:`combined`.
        Any repair that buys costs at least the cheapest device plus the windows' costs with free devices."""
        sets: list[frozenset[str]] = []
        carried: dict[str, str] = {}
        free = replace(self.costs, add_device=0.01, add_device_per_price=0.0)
        bound = 0
        for w in wins:
            models = self.solve(w, self.cell, extra, carried, 1, free)
            if not models:
                return [], 0
            bought = frozenset(e.e.a for e in models[0][s.Edit] if isinstance(e.e, edits.Add))
            bound += (models[0].cost[0] if models[0].cost else 0) - len(extra)  # at most one hundredth each
            carried.update(self._carried(w, models[0]))
            if bought and bought not in sets:
                sets.append(bought)
        if len(sets) > 1:
            sets.append(frozenset().union(*sets))
        by_id = {d.id: d for d in extra}
        return [tuple(by_id[a] for a in sorted(x)) for x in sets], bound

    def combined(self, wins: list[Window], added: tuple[DeviceDescription, ...]
                 ) -> list[tuple[int, tuple[_Part, ...], tuple[str, ...]]]:
        """The ``top`` cheapest combinations of the windows' repairs in the cell plus ``added``."""
        cell = Cell(self.cell.name, self.cell.devices + added, self.cell.file)
        price = sum(repairs.add_cost(self.costs, d) for d in added)
        names = tuple(d.id for d in added)
        per_window: list[_Parts] = []
        carried: dict[str, str] = {}
        for w in wins:
            first = min(self.top, FIRST)
            models = self.solve(w, cell, (), carried, first)
            if len(models) < first < self.top:  # fewer than asked: the whole answer judges how many there are
                first, models = self.top, self.solve(w, cell, (), carried, self.top)
            if not models:
                return []
            rest = None if first == self.top else self._rest(w, cell, dict(carried))
            per_window.append(_Parts([self.part(w, m) for m in models], rest))
            carried.update(self._carried(w, models[0]))
        return [(price + sum(p.cost for p in combo), combo, names) for combo in k_best(per_window, self.top)]

    def _rest(self, w: Window, cell: Cell, carried: dict[str, str]) -> Callable[[], list[_Part]]:
        """All ``top`` repairs of window ``w``, entering it as it did (its first ones are those solved before:
        the solver finds them in the same order)."""
        return lambda: [self.part(w, m) for m in self.solve(w, cell, (), carried, self.top)]

    def solve(self, w: Window, cell: Cell, extra: Sequence[DeviceDescription], carried: dict[str, str],
              top: int, costs: RepairCosts | None = None) -> list[Model]:
        """The window's best repairs, entering in the checked states (and those earlier windows left behind)."""
        entry = {**self.chain.states(w.first), **carried}
        entering = Cell(cell.name, tuple(replace(d, initial=entry.get(d.id, d.initial)) for d in cell.devices),
                        cell.file)
        bought = [replace(d, initial=entry.get(d.id, d.initial)) for d in extra]
        steps = self.chain.task.steps[w.first - 1:w.last]
        sub = Task(self.chain.task.name, tuple(replace(st, index=k) for k, st in enumerate(steps, start=1)),
                   self.chain.task.file)
        facts = (cell_program(self.book, entering, bought)
                 + repairs.task_program(sub, [*cell.devices, *bought], self.book, self.known)
                 + program(repairs.horizon(sub, self.per_gap, None))
                 + program(repairs.cost_facts(costs or self.costs, self.book.processes, bought))
                 + program(s.Catalogue(d.id) for d in bought)
                 + program(s.ExitState(d, x) for d, x in sorted(self.chain.exits(w).items())))
        key = (facts, top, tuple((st.command, repr(sorted(st.bind.items())), repr(sorted(st.params.items())))
                                 for st in steps))
        if key not in self.memo:  # a repetitive task has many windows alike: solve each kind once
            self.memo[key] = solver.optimise(solver.WINDOW, facts, top, repairs.forbid,
                                             lambda m: repairs.outcome(m, sub))
        return self.memo[key]

    def _carried(self, w: Window, model: Model) -> dict[str, str]:
        """States the window leaves devices in that no later original step uses (they stay so)."""
        return {a.d: a.x for a in model[s.LeftIn] if self.chain.last_use.get(a.d, 0) <= w.last}

    def part(self, w: Window, model: Model) -> _Part:
        """A window's model with its edits renumbered to the original steps."""
        steps = self.chain.task.steps[w.first - 1:w.last]
        sub = Task(self.chain.task.name, tuple(replace(st, index=k) for k, st in enumerate(steps, start=1)),
                   self.chain.task.file)
        moved = tuple(e.e.shifted(w.first - 1) for e in model[s.Edit])
        runs = repairs.repaired_runs(model, sub)
        origins = tuple(i + w.first - 1 if i else 0 for i, _ in runs)
        resets = sorted({e.e.i for e in model[s.Edit] if isinstance(e.e, edits.Reset)})
        bound = tuple((i + w.first - 1, tuple(sorted(repairs.bound_at(model, i).items()))) for i in resets)
        return _Part(w, model.cost[0] if model.cost else 0, moved, tuple(st for _, st in runs), origins,
                     bound)

    def read(self, rank: int, combo: tuple[int, tuple[_Part, ...], tuple[str, ...]],
             reader: repairs._EditReader) -> Repair:
        """One combination as a :class:`Repair` of the whole task."""
        cost, parts, added = combo
        bound = {i: dict(b) for p in parts for i, b in p.reset_bound}
        reader = reader.with_bound(lambda i: bound.get(i, {}))
        terms = [t for p in parts for t in p.edits] + [edits.Add(a) for a in added]
        read = sorted((reader.read(t) for t in terms), key=lambda e: (e.step or 0, e.kind, e.text))
        task = self.chain.task
        steps: list[Step] = []
        origins: list[int] = []
        start = 1
        for p in parts:
            steps += task.steps[start - 1:p.window.first - 1]
            origins += range(start, p.window.first)
            steps += p.steps
            origins += p.origins
            start = p.window.last + 1
        steps += task.steps[start - 1:]
        origins += range(start, len(task.steps) + 1)
        steps = [st.at(k) for k, st in enumerate(steps, start=1)]
        repaired = Task(task.name, tuple(steps), task.file, task.description,
                        repairs.folded_repeat(steps, task.repeat))
        return Repair(rank, cost / 100, tuple(read), repaired, added, tuple(origins))
