"""Repairs lifted onto the written task, so that its loops and branches stay.

The repairer edits the flat steps (:mod:`plugnproduce.description.flow`: a loop's body twice, a
branch's steps after its step). Each flat position comes from one written step: a removed flat
step removes that written step, a changed binding or parameter changes it, and a step inserted
before a flat position goes before that position's written step in the same container (top
level, loop body, branch body), or where the flat order says the same thing: at the end of the
loop or branch body that ends right before it, or before the loop that starts there. The edits
of a loop body's two copies are united. The written result is checked again with the real check
(every path); when no placement is plausible, or the copies' edits disagree, the repair keeps its
flat steps and says why in :attr:`~plugnproduce.reasoning.asp.results.Repair.unrolls`.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from plugnproduce.description.flow import Branch, Loop
from plugnproduce.description.model import Cell, DeviceDescription, Step, Task
from plugnproduce.reasoning.asp.results import Repair
from plugnproduce.reasoning.checks.plausibility import check

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

Key = tuple[object, ...]
"""A written item (``("step", pos)``, ``("loop", entry)``, ``("new", n)``) or a container of items
(``("top",)``, ``("loop", entry)``, ``("branch", pos, outcome)``); ``pos`` is a step's first flat position."""
Gap = tuple[Key, Key | None]
"""A place for inserted steps: in a container, before an item (None: at its end)."""

MAX_PLACEMENTS = 16
"""Most combinations of placements of a repair's inserted steps checked again."""

UNROLLS = "this repair writes the task's loops and branches out step by step: "


class _Unliftable(Exception):
    """The repair's edits have no place in the written task (the reason is the message)."""


@dataclass
class _Node:
    """A written item: a step with its branches, or a loop with its body."""

    key: Key
    step: Step | None = None
    loop: Loop | None = None
    body: list[_Node] = field(default_factory=list)
    branches: list[tuple[Branch, list[_Node]]] = field(default_factory=list)


@dataclass
class _Written:
    """The written task as items, with the container of each item and the flat positions of each step."""

    task: Task
    parent: dict[Key, Key] = field(default_factory=dict)
    items: list[_Node] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.items = self.tree(("top",), 1, len(self.task.steps), False)

    def tree(self, container: Key, start: int, end: int, in_loop: bool) -> list[_Node]:
        """The items of flat positions ``start`` to ``end`` (as the task writer reads them)."""
        out: list[_Node] = []
        i = start
        while i <= end:
            loop = None if in_loop else next((lp for lp in self.task.loops if lp.entry == i), None)
            if loop is not None:
                key: Key = ("loop", i)
                out.append(_Node(key, loop=loop, body=self.tree(key, loop.entry, loop.first - 1, True)))
                i = loop.last + 1
            else:
                key = ("step", i)
                bs = self.task.branches_of(i)
                out.append(_Node(key, step=self.task.steps[i - 1], branches=[
                    (b, self.tree(("branch", i, b.outcome), b.first, b.last, in_loop)) for b in bs]))
                i = max([i, *(b.last for b in bs)]) + 1
            self.parent[key] = container
        return out

    def canon(self, q: int) -> int:
        """The written step's first flat position (a loop's later iterations map onto its first)."""
        lp = next((lp for lp in self.task.loops if lp.first <= q <= lp.last), None)
        return q - (lp.first - lp.entry) if lp else q

    def copies(self, c: int) -> list[int]:
        """The flat positions of the written step at first position ``c``."""
        lp = next((lp for lp in self.task.loops if lp.entry <= c < lp.first), None)
        return [c, c + lp.first - lp.entry] if lp else [c]

    def gaps(self, before: int, after: int) -> list[Gap]:
        """The written places of a flat insertion between positions ``after`` and ``before`` (0: none)."""
        out: list[Gap] = []
        if before:
            out.append((self.parent[("step", self.canon(before))], ("step", self.canon(before))))
        if after:
            c = self.canon(after)
            out += [(("loop", lp.entry), None) for lp in self.task.loops if lp.first - 1 == c]
            out += [(("branch", b.step, b.outcome), None) for b in self.task.branches
                    if b.last == c and self.canon(b.step) == b.step]
        out += [(self.parent[("loop", lp.entry)], ("loop", lp.entry)) for lp in self.task.loops if lp.entry == before]
        if not before:
            out.append((("top",), None))
        return list(dict.fromkeys(out))


def _sig(step: Step) -> tuple[str, str, str]:
    return step.command, repr(sorted(step.bind.items())), repr(sorted(step.params.items()))


def _written_steps(w: _Written, kept: dict[int, Step]) -> dict[int, Step | None]:
    """Each written step as the repair leaves it (None: removed), the edits of a loop body's copies united."""
    out: dict[int, Step | None] = {}
    for c in sorted({w.canon(q) for q in range(1, len(w.task.steps) + 1)}):
        versions = [kept.get(q) for q in w.copies(c)]
        if any(v is None for v in versions):
            out[c] = None
            continue
        changed = {_sig(v): v for v in versions if v is not None and _sig(v) != _sig(w.task.steps[c - 1])}
        if len(changed) > 1:
            raise _Unliftable(f"the iterations of the loop repair step {c} ({w.task.steps[c - 1].command}) "
                              "differently")
        out[c] = next(iter(changed.values()), versions[0])
    return out


def _insert_groups(w: _Written, repair: Repair) -> list[tuple[list[Gap], list[Step]]]:
    """The runs of inserted steps, each with the written places it may go (the flat order's own first)."""
    groups: dict[tuple[tuple[Gap, ...], tuple[tuple[str, str, str], ...]], list[Step]] = {}
    run: list[Step] = []
    after = 0
    for origin, step in [*zip(repair.origins, repair.task.steps, strict=True), (0, None)]:
        if origin == 0 and step is not None:
            run.append(step)
            continue
        if run:
            gaps = tuple(w.gaps(origin, after))
            groups.setdefault((gaps, tuple(_sig(s) for s in run)), run)
            run = []
        after = origin
    return [(list(gaps), steps) for (gaps, _), steps in groups.items()]


def _swapped(w: _Written, repair: Repair) -> list[_Node]:
    """The written items with the repair's swaps of two neighbouring flat steps done to their written steps."""
    pairs = {(("step", w.canon(e.step)), ("step", w.canon(e.step + 1))) for e in repair.edits
             if e.kind == "swap" and e.step is not None}
    done: set[tuple[Key, Key]] = set()

    def walk(items: list[_Node]) -> list[_Node]:
        out = [dataclasses.replace(n, body=walk(n.body), branches=[(b, walk(body)) for b, body in n.branches])
               for n in items]
        for a, b in pairs:
            at = next((k for k, n in enumerate(out[:-1]) if n.key == a and out[k + 1].key == b), None)
            if at is not None:
                out[at], out[at + 1] = out[at + 1], out[at]
                done.add((a, b))
        return out

    items = walk(w.items)
    if done != pairs:
        raise _Unliftable("it swaps steps that are not neighbours in one list of the task file")
    return items


def _rebuild(items: list[_Node], container: Key, steps: dict[int, Step | None],
             inserts: dict[Gap, list[_Node]]) -> list[_Node]:
    """The items with the repair's edits applied."""
    out: list[_Node] = []
    for node in items:
        out += inserts.get((container, node.key), [])
        if node.loop is not None:
            out.append(dataclasses.replace(node, body=_rebuild(node.body, node.key, steps, inserts)))
            if not out[-1].body:
                raise _Unliftable("it leaves the loop without steps")
            continue
        if node.key[0] == "new":
            out.append(node)
            continue
        pos = int(str(node.key[1]))
        step = steps.get(pos, node.step)
        if step is None:
            if node.branches:
                raise _Unliftable(f"it removes step {pos}, whose branches would lose their step")
            continue
        branches = [(b, _rebuild(body, ("branch", pos, b.outcome), steps, inserts)) for b, body in node.branches]
        if any(not body for _, body in branches):
            raise _Unliftable(f"it leaves a branch of step {pos} without steps")
        out.append(dataclasses.replace(node, step=step, branches=branches))
    return out + inserts.get((container, None), [])


@dataclass
class _Flat:
    steps: list[Step] = field(default_factory=list)
    loops: list[Loop] = field(default_factory=list)
    branches: list[Branch] = field(default_factory=list)
    origins: list[int] = field(default_factory=list)
    """Each step's flat position in the written task (0: inserted), as :attr:`Repair.origins` says."""

    def add(self, items: list[_Node]) -> None:
        """Flatten items onto the steps (a loop's body twice, a branch's steps after its step)."""
        for node in items:
            if node.loop is not None:
                entry, known = len(self.steps) + 1, len(self.branches)
                self.add(node.body)
                first = len(self.steps) + 1
                n = first - entry
                self.steps += [dataclasses.replace(s, index=s.index + n) for s in self.steps[entry - 1:]]
                shift = node.loop.first - node.loop.entry  # where the written task's second copy of its body is
                self.origins += [q + shift if q else 0 for q in self.origins[entry - 1:]]
                self.branches += [dataclasses.replace(b, step=b.step + n, first=b.first + n, last=b.last + n)
                                  for b in self.branches[known:]]
                self.loops.append(dataclasses.replace(node.loop, entry=entry, first=first, last=len(self.steps)))
                continue
            if node.step is None:
                continue
            index = len(self.steps) + 1
            self.steps.append(dataclasses.replace(node.step, index=index))
            self.origins.append(int(str(node.key[1])) if node.key[0] == "step" else 0)
            for b, body in node.branches:
                first = len(self.steps) + 1
                self.add(body)
                self.branches.append(dataclasses.replace(b, step=index, first=first, last=len(self.steps)))


def _placements(w: _Written, repair: Repair) -> list[tuple[Task, tuple[int, ...]]]:
    """The written tasks the repair may stand for, the flat order's own placement first, each with the written
    task's flat position of each of its steps (0: inserted)."""
    steps = _written_steps(w, {q: s for q, s in zip(repair.origins, repair.task.steps, strict=True) if q})
    items = _swapped(w, repair)
    groups = _insert_groups(w, repair)
    out: list[tuple[Task, tuple[int, ...]]] = []
    for choice in itertools.islice(itertools.product(*(gaps for gaps, _ in groups)), MAX_PLACEMENTS):
        inserts: dict[Gap, list[_Node]] = {}
        for gap, (_, run) in zip(choice, groups, strict=True):
            nodes = [_Node(("new", id(s)), step=s) for s in run]
            if gap in inserts and [_sig(n.step) for n in inserts[gap] if n.step] != [_sig(s) for s in run]:
                break  # two runs of different steps at one place: the copies disagree
            inserts[gap] = nodes
        else:
            flat = _Flat()
            flat.add(_rebuild(items, ("top",), steps, inserts))
            t = w.task
            out.append((Task(t.name, tuple(flat.steps), t.file, t.description, 1, tuple(flat.loops),
                             tuple(flat.branches)), tuple(flat.origins)))
    return out


def lift(repair: Repair, task: Task, cell: Cell, knowledge: Knowledge) -> Repair:
    """The repair with its resulting task written like ``task`` (its loops and branches kept) when that is
    plausible on every path in ``cell``; else with its flat steps and :attr:`Repair.unrolls` saying why."""
    if not (task.loops or task.branches) or len(repair.origins) != len(repair.task.steps):
        return repair
    flat = dataclasses.replace(repair.task, loops=(), branches=())
    if any(len(task.loops_at(lp.entry)) > 1 for lp in task.loops):
        return dataclasses.replace(repair, task=flat, unrolls=UNROLLS + "the task has a loop inside a loop")
    w = _Written(task)
    try:
        candidates = _placements(w, repair)
    except _Unliftable as e:
        return dataclasses.replace(repair, task=flat, unrolls=UNROLLS + str(e))
    first_problem = ""
    for written, origins in candidates:
        result = check(written, cell, knowledge)
        if result.plausible:  # its side effects are those of the written steps it inserts or changes
            return dataclasses.replace(repair, task=written, origins=origins)
        first_problem = first_problem or (result.problems[0].text if result.problems else "")
    why = (f"kept in the loop or branch it is not plausible ({first_problem})" if candidates
           else "the loop's iterations repair it differently")
    return dataclasses.replace(repair, task=flat, unrolls=UNROLLS + why)


def lifted(repairs: Sequence[Repair], task: Task, cell: Cell, knowledge: Knowledge,
           catalogue: Sequence[DeviceDescription] = ()) -> list[Repair]:
    """Each repair lifted onto the written task (:func:`lift`), checked in the cell with the devices it adds."""
    out = []
    for r in repairs:
        added = tuple(d for d in catalogue if d.id in r.added_devices and all(d.id != c.id for c in cell.devices))
        out.append(lift(r, task, dataclasses.replace(cell, devices=cell.devices + added), knowledge))
    return out
