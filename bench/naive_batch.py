"""The naive reference for the batch benchmark: the reasoner's rules applied by plain brute force.

It reads the same facts the encodings read (``facts.py``: devices, processes, tasks) and applies
``roles.lp``, ``offered.lp``, ``resolve.lp``, ``chain.lp``, ``params.lp``, the acceptance check
and the devices' own limits (``contracts.refuses``) literally, per configuration, with Python
sets; nothing is shared between configurations. The cheapest purchase tries every set of up to
``MAX_BUY`` catalogue devices, keeps those that make every task plausible and of which no
smaller such set is a part, and sorts them by cost, then size, then the devices' order by
(cost, id).
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from collections.abc import Sequence

from plugnproduce.description.model import DeviceDescription, ProcessDescription, Task
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning import schema as s
from plugnproduce.reasoning.accepts import accepts
from plugnproduce.reasoning.contracts import normalised, refuses
from plugnproduce.reasoning.facts import device_facts, process_facts, task_facts

MAX_BUY = 4
"""Largest purchase the reference tries."""


class Naive:
    """The facts of a catalogue, its processes and tasks; answers one configuration at a time."""

    def __init__(self, catalogue: Sequence[DeviceDescription], tasks: Sequence[tuple[str, Task]],
                 taxonomy: Taxonomy, processes: Sequence[ProcessDescription]) -> None:
        tasks = [(name, normalised(t, processes)[0]) for name, t in tasks]
        atoms = [a for p in processes for a in process_facts(p)]
        atoms += [a for d in catalogue for a in device_facts(d, taxonomy, processes)]
        atoms += [a for name, t in tasks for a in task_facts(t, name)]
        self.by: dict[type, list] = defaultdict(list)
        for a in atoms:
            self.by[type(a)].append(a)
        self.catalogue = {d.id: d for d in catalogue}
        self.taxonomy = taxonomy
        self.params = {(p.id, par.name): par for p in processes for par in p.parameters}
        self.tasks = [name for name, _ in tasks]
        self.given = {(name, st.index): dict(st.params) for name, t in tasks for st in t.steps}
        self.declared = {p.id: p.parameters for p in processes}
        self.can_play = self._can_play()
        self.bad_value = self._bad_values()

    def _can_play(self) -> set[tuple[str, str, str]]:
        edges = defaultdict(set)
        for e in self.by[s.Edge]:
            edges[(e.d, e.x)].add(e.y)
        is_ = {(a.d, a.x, a.c) for a in self.by[s.StateIs]}
        states = defaultdict(set)
        for a in self.by[s.ChartState]:
            states[a.d].add(a.x)
        skills = {(a.d, a.s) for a in self.by[s.HasSkill]}
        region = defaultdict(dict)
        for a in self.by[s.RegionState]:
            region[(a.p, a.r)][a.i] = a.c
        lacking = {(a.p, a.r, a.d) for a in self.by[s.MissingArg]}
        out = set()
        for q in self.by[s.Requires]:
            for d in [x.d for x in self.by[s.Device]]:
                if (d, q.s) not in skills:
                    continue
                concepts = [region[(q.p, q.r)][i] for i in sorted(region[(q.p, q.r)])]
                here = {x for x in states[d] if (d, x, concepts[0]) in is_}
                for c in concepts[1:]:
                    here = {y for x in here for y in _reach(edges, d, x) if (d, y, c) in is_}
                if here and (q.p, q.r, d) not in lacking:
                    out.add((q.p, q.r, d))
        return out

    def _bad_values(self) -> set[tuple[str, int]]:
        param = {(a.p, a.n): a.ty for a in self.by[s.Param]}
        low = {(a.p, a.n): a.v for a in self.by[s.ParamMin]}
        high = {(a.p, a.n): a.v for a in self.by[s.ParamMax]}
        kinds = {(a.t, a.i, a.n, a.k) for a in self.by[s.ValueKind]}
        nums = {(a.t, a.i, a.n): a.v for a in self.by[s.ValueNum]}
        step = {(a.t, a.i): a.p for a in self.by[s.StepFact]}
        procs = {a.p for a in self.by[s.Process]}
        out = set()
        for g in self.by[s.Given]:
            p = step[(g.t, g.i)]
            ty = param.get((p, g.n))
            if ty is None:
                if p in procs:
                    out.add((g.t, g.i))
                continue
            fits = (g.t, g.i, g.n, ty) in kinds or (ty == "decimal" and (g.t, g.i, g.n, "integer") in kinds)
            v = nums.get((g.t, g.i, g.n))
            if not fits or (v is not None and ((p, g.n) in low and v < low[(p, g.n)]
                                               or (p, g.n) in high and v > high[(p, g.n)])):
                out.add((g.t, g.i))
        return out

    def offered(self, members: set[str]) -> list[str]:
        """The processes a configuration offers, sorted."""
        roles = defaultdict(list)
        for r in self.by[s.Role]:
            roles[r.p].append(r.r)
        return sorted(p.p for p in self.by[s.Process]
                      if all(any((p.p, r, d) in self.can_play for d in members) for r in roles[p.p]))

    def plausible(self, members: set[str]) -> list[str]:
        """The tasks plausible in a configuration, in task order."""
        return [t for t in self.tasks if self._plausible(t, members)]

    def _plausible(self, t: str, members: set[str]) -> bool:
        steps = sorted((a.i, a.p) for a in self.by[s.StepFact] if a.t == t)
        procs = {a.p for a in self.by[s.Process]}
        order = sorted((a.p, a.k, a.r) for a in self.by[s.RoleOrder])
        binds = {(a.i, a.r): a.d for a in self.by[s.Bind] if a.t == t}
        bound: list[list[tuple[str, str]]] = []
        for i, p in steps:
            if p not in procs or (t, i) in self.bad_value:
                return False
            roles = [r for q, _, r in order if q == p]
            if any(r not in roles for j, r in binds if j == i):
                return False
            here = []
            for r in roles:
                if (i, r) in binds:
                    d = binds[(i, r)]
                    if d not in members or (p, r, d) not in self.can_play:
                        return False
                    here.append((r, d))
                else:
                    cands = [d for d in members if (p, r, d) in self.can_play]
                    if len(cands) != 1:
                        return False
                    here.append((r, cands[0]))
            for name in self.given.get((t, i), {}):
                par = self.params.get((p, name))
                player = dict(here).get(par.role) if par else None
                if player is not None and not accepts(self.catalogue[player], par.quantity, self.taxonomy):
                    return False
            for par in self.declared[p]:
                value = self.given.get((t, i), {}).get(par.name, par.default)
                player = dict(here).get(par.role)
                if player is not None and value is not None and refuses(self.catalogue[player], value, par):
                    return False
            bound.append(here)
        return self._chain(steps, bound, members)

    def _chain(self, steps: list[tuple[int, str]], bound: list[list[tuple[str, str]]], members: set[str]) -> bool:
        at = {d: {a.x for a in self.by[s.Initial] if a.d == d} for d in members}
        first = {(a.p, a.r): a.c for a in self.by[s.RegionState] if a.i == 1}
        is_ = {(a.d, a.x, a.c) for a in self.by[s.StateIs]}
        for (_, p), here in zip(steps, bound, strict=True):
            for d in {d for _, d in here}:
                states = at[d]
                for r in [r for r, e in here if e == d]:
                    leaves = {(a.x, a.y) for a in self.by[s.Leaves] if (a.p, a.r, a.d) == (p, r, d)}
                    after = set()
                    for x in states:
                        k = first.get((p, r))
                        starts = {y for x2, y in leaves if x2 == x}
                        if k is not None and ((d, x, k) not in is_ or not starts):
                            return False
                        after |= starts or {a.y for a in self.by[s.Recovers] if (a.p, a.r, a.d) == (p, r, d)}
                    states = after
                at[d] = states
        return True

    def purchases(self, members: set[str], top: int) -> list[tuple[tuple[str, ...], int]]:
        """The ``top`` cheapest purchases of up to MAX_BUY devices none of which is superfluous."""
        if len(self.plausible(members)) == len(self.tasks):
            return []
        cost = {d: round(x.cost) for d, x in self.catalogue.items()}
        rank = {d: n for n, d in enumerate(sorted(self.catalogue, key=lambda d: (cost[d], d)))}
        free = sorted(set(self.catalogue) - members)
        works: list[frozenset[str]] = []
        for size in range(1, MAX_BUY + 1):
            for buy in itertools.combinations(free, size):
                b = frozenset(buy)
                if (not any(w < b for w in works)
                        and len(self.plausible(members | b)) == len(self.tasks)):
                    works.append(b)
        ranked = sorted(works, key=lambda b: (sum(cost[d] for d in b), len(b), sorted(rank[d] for d in b)))
        return [(tuple(sorted(b)), sum(cost[d] for d in b)) for b in ranked[:top]]


def _reach(edges: dict[tuple[str, str], set[str]], d: str, x: str) -> set[str]:
    seen, todo = {x}, [x]
    while todo:
        for y in edges.get((d, todo.pop()), ()):
            if y not in seen:
                seen.add(y)
                todo.append(y)
    return seen
