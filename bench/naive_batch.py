"""The brute-force reference of the batch benchmark: a straightforward per-configuration script.

    python bench/naive_batch.py CONFIGS.jsonl --catalogue DIR --task TASK... -o OUT.jsonl

It reads the same facts the encodings read (``facts.py``: devices, processes, tasks), indexes them
once in plain dicts, and then answers each configuration on its own with Python sets, nothing
shared between configurations: which roles each device can play (its skills, by subsumption, and
the ordered states of the role's region reachable in its chart), the offered processes, each
task's role binding, its parameter values against the bound devices' argument contracts (the
quantity accepted, the device's own limits), and the chain of states through the task. As a
script it writes one JSON line per configuration: ``config``, ``devices``, ``offered``,
``plausible`` (no purchases: the batch computes those on top).

:meth:`Naive.purchases` (for the benchmark's agreement check, not timed) tries every set of up to
``MAX_BUY`` catalogue devices, keeps those that make every task plausible and of which no smaller
such set is a part, and sorts them by cost, then size, then the devices' order by (cost, id).
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

from plugnproduce.description.model import DeviceDescription, ProcessDescription, Task
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.facts import device_facts, process_facts, task_facts
from plugnproduce.reasoning.checks.accepts import accepts
from plugnproduce.reasoning.checks.contracts import normalised, refuses

MAX_BUY = 4
"""Largest purchase the reference tries."""

Step = tuple[int, str, list[str], dict[str, str], dict[str, object]]
"""A task's step: index, process, the process's roles in order, the devices bound by name, the values given."""


class Naive:
    """The facts of a catalogue, its processes and tasks, indexed; answers one configuration at a time."""

    def __init__(self, catalogue: Sequence[DeviceDescription], tasks: Sequence[tuple[str, Task]],
                 taxonomy: Taxonomy, processes: Sequence[ProcessDescription]) -> None:
        tasks = [(name, normalised(t, processes)[0]) for name, t in tasks]
        atoms = [a for p in processes for a in process_facts(p)]
        atoms += [a for d in catalogue for a in device_facts(d, taxonomy, processes)]
        atoms += [a for name, t in tasks for a in task_facts(t, name)]
        by: dict[type, list] = defaultdict(list)
        for a in atoms:
            by[type(a)].append(a)
        self.by = by
        self.catalogue = {d.id: d for d in catalogue}
        self.taxonomy = taxonomy
        self.tasks = [name for name, _ in tasks]
        self.params = {(p.id, par.name): par for p in processes for par in p.parameters}
        self.declared = {p.id: p.parameters for p in processes}
        self.processes = sorted({a.p for a in by[s.Process]})
        order = sorted((a.p, a.k, a.r) for a in by[s.RoleOrder])
        self.roles: dict[str, list[str]] = defaultdict(list)
        for p, _, r in order:
            self.roles[p].append(r)
        self.is_ = {(a.d, a.x, a.c) for a in by[s.StateIs]}
        self.first = {(a.p, a.r): a.c for a in by[s.RegionState] if a.i == 1}
        self.initial: dict[str, set[str]] = defaultdict(set)
        for a in by[s.Initial]:
            self.initial[a.d].add(a.x)
        self.leaves: dict[tuple[str, str, str], dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
        for a in by[s.Leaves]:
            self.leaves[(a.p, a.r, a.d)][a.x].add(a.y)
        self.recovers: dict[tuple[str, str, str], set[str]] = defaultdict(set)
        for a in by[s.Recovers]:
            self.recovers[(a.p, a.r, a.d)].add(a.y)
        self.can_play = self._can_play()
        self.bad_value = self._bad_values()
        self.steps = {name: self._steps(name, t) for name, t in tasks}

    def _steps(self, name: str, task: Task) -> list[Step]:
        process = {(a.t, a.i): a.p for a in self.by[s.StepFact]}
        binds: dict[int, dict[str, str]] = defaultdict(dict)
        for a in self.by[s.Bind]:
            if a.t == name:
                binds[a.i][a.r] = a.d
        return [(st.index, process[(name, st.index)], self.roles.get(process[(name, st.index)], []),
                 binds[st.index], dict(st.params)) for st in task.steps]

    def _can_play(self) -> set[tuple[str, str, str]]:
        """(process, role, device): the device has the role's skill (by subsumption) and its chart reaches the
        role's region states in order."""
        edges = defaultdict(set)
        for e in self.by[s.Edge]:
            edges[(e.d, e.x)].add(e.y)
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
                here = {x for x in states[d] if (d, x, concepts[0]) in self.is_}
                for c in concepts[1:]:
                    here = {y for x in here for y in _reach(edges, d, x) if (d, y, c) in self.is_}
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
        return [p for p in self.processes
                if all(any((p, r, d) in self.can_play for d in members) for r in self.roles[p])]

    def plausible(self, members: set[str]) -> list[str]:
        """The tasks plausible in a configuration, in task order."""
        return [t for t in self.tasks if self._plausible(t, members)]

    def _plausible(self, t: str, members: set[str]) -> bool:
        bound: list[list[tuple[str, str]]] = []
        for i, p, roles, binds, given in self.steps[t]:
            if p not in self.declared or (t, i) in self.bad_value or any(r not in roles for r in binds):
                return False
            here = []
            for r in roles:
                if r in binds:
                    d = binds[r]
                    if d not in members or (p, r, d) not in self.can_play:
                        return False
                    here.append((r, d))
                else:
                    cands = [d for d in members if (p, r, d) in self.can_play]
                    if len(cands) != 1:
                        return False
                    here.append((r, cands[0]))
            if not self._values_fit(p, dict(here), given):
                return False
            bound.append(here)
        return self._chain(t, bound)

    def _values_fit(self, p: str, players: dict[str, str], given: dict[str, object]) -> bool:
        """Each value given goes to a device that accepts its quantity; each value sent (given or the default)
        keeps the bound device's own limits."""
        for name in given:
            par = self.params.get((p, name))
            player = players.get(par.role) if par else None
            if player is not None and not accepts(self.catalogue[player], par.quantity, self.taxonomy):
                return False
        for par in self.declared[p]:
            value = given.get(par.name, par.default)
            player = players.get(par.role)
            if player is not None and value is not None and refuses(self.catalogue[player], value, par):
                return False
        return True

    def _chain(self, t: str, bound: list[list[tuple[str, str]]]) -> bool:
        at: dict[str, set[str]] = {}
        for (_, p, _, _, _), here in zip(self.steps[t], bound, strict=True):
            for d in dict.fromkeys(d for _, d in here):
                states = at.get(d, self.initial[d])
                for r in [r for r, e in here if e == d]:
                    leaves = self.leaves.get((p, r, d), {})
                    k = self.first.get((p, r))
                    after: set[str] = set()
                    for x in states:
                        starts = leaves.get(x, set())
                        if k is not None and ((d, x, k) not in self.is_ or not starts):
                            return False
                        after |= starts or self.recovers.get((p, r, d), set())
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


def main() -> None:
    """Answer a JSONL file of configurations as a script: offered processes and plausible tasks per line."""
    from plugnproduce import service
    from plugnproduce.batch.batches import task_names

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("configs", type=Path)
    parser.add_argument("--catalogue", type=Path)
    parser.add_argument("--task", type=Path, action="append", default=[])
    parser.add_argument("-o", "--output", type=Path)
    args = parser.parse_args()
    k = service.knowledge()
    catalogue = service.catalogue(args.catalogue, k)
    ref = Naive(catalogue, task_names([service.task(t) for t in args.task]), k.taxonomy, k.processes)
    out = args.output.open("w", encoding="utf-8") if args.output else sys.stdout
    with args.configs.open(encoding="utf-8") as f, out:
        for line in f:
            doc = json.loads(line)
            members = set(doc["devices"])
            out.write(json.dumps({"config": doc["config"], "devices": doc["devices"], "offered": ref.offered(members),
                                  "plausible": ref.plausible(members)}) + "\n")


if __name__ == "__main__":
    main()
