"""Plans from goals: clingo chooses the commands, their order, bindings and where each value comes from.

The horizon grows one step at a time (rules/plan.lp, incremental). The first horizon with a plan
gives the fewest steps; the search then looks :data:`LOOK_FURTHER` steps beyond it for a plan that
measures more of its values (a pick pose the bin-picking PC reports rather than a default), and
keeps the best: fewest values left to defaults that the cell could measure, then fewest steps,
then fewest device roles. With ``minimize="cycle-time"`` it compares, at each horizon searched, up to
:data:`MOST_PLANS` plans that are best by those criteria, and keeps the one of least estimated cycle time
(:mod:`plugnproduce.timing`) before fewest steps. The plan is written as a task file and read back by the task reader,
so it is checked, verified and run like any task.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import yaml

from plugnproduce.description.goalfile import Goal, check_terms
from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Task
from plugnproduce.description.outcomes import falling_under
from plugnproduce.description.taskfile import parse_task, task_to_yaml
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.iris import concept_value, local_name
from plugnproduce.ontology.names import did_you_mean
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.planning import schema as ps
from plugnproduce.reasoning.asp import solver
from plugnproduce.reasoning.asp.facts import fact_book
from plugnproduce.reasoning.asp.terms import Atom, Model, program
from plugnproduce.reasoning.checks.offers import capabilities, cell_program
from plugnproduce.safeio import PlainDumper

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

MAX_STEPS = 12
"""Longest plan searched for, in steps (a loop's body)."""
LOOK_FURTHER = 3
"""Steps beyond the shortest plan searched for one that measures more of its values."""
MOST_PLANS = 16
"""With ``minimize="cycle-time"``: the optimal plans per horizon whose cycle times are compared."""
MINIMIZE = ("steps", "cycle-time")
"""What a plan minimises after the values it measures: its steps (then its device roles), or its estimated
cycle time (then its steps, then its roles)."""


@dataclass(frozen=True)
class Plan:
    """A task that reaches the goal, as a task file and as read back."""

    goal: Goal
    text: str
    task: Task
    steps: int
    """Steps of the plan (of the loop's body, for a goal with ``until``)."""
    blind: tuple[tuple[int, str], ...]
    """(step, parameter) left to its default although the cell could measure it."""
    wasted: tuple[tuple[int, str], ...] = ()
    """(step, output) that another command could take, which no later step takes."""
    cycle_time: float | None = None
    """The estimated cycle time it was chosen by (``minimize="cycle-time"``; None otherwise)."""


@dataclass(frozen=True)
class Unreachable:
    """A goal no plan reaches in this cell, why, and the cheapest catalogue device that would make one."""

    goal: Goal
    reasons: tuple[str, ...]
    purchase: DeviceDescription | None = None


def plan(goal: Goal, cell: Cell, knowledge: Knowledge,
         catalogue: Sequence[DeviceDescription] = (), max_steps: int = MAX_STEPS,
         source: str | None = None, minimize: str = "steps") -> Plan | Unreachable:
    """Plan ``goal`` in ``cell`` from its devices' states (their ``initial``: chart or reported).

    ``source`` names the written task file (in messages and ``Task.file``); with a catalogue, an
    unreachable goal names the cheapest device whose purchase makes it reachable. ``minimize``: one of
    :data:`MINIMIZE`.
    """
    if minimize not in MINIMIZE:
        raise ValueError(f"minimize {minimize!r}: expected one of {', '.join(MINIMIZE)}")
    by_id = knowledge.processes_by_id
    check_goal(goal, cell, knowledge)
    name = source or f"{goal.name}.yaml"
    if minimize == "cycle-time":
        fastest = _fastest(goal, cell, knowledge, max_steps, name)
        if isinstance(fastest, Plan):
            return fastest
    found = _search(goal, cell, knowledge, max_steps)
    if isinstance(found, Model):
        return _written(goal, found, by_id, name)
    for device in sorted((d for d in catalogue if d.id not in {c.id for c in cell.devices}),
                         key=lambda d: (d.cost, d.id)):
        if isinstance(_search(goal, cell.with_device(device), knowledge, max_steps), Model):
            return Unreachable(goal, found, device)
    return Unreachable(goal, found)


# ------------------------------------------------------------------ the goal against the knowledge


def check_goal(goal: Goal, cell: Cell, knowledge: Knowledge) -> None:
    """Bad input in the goal file: unknown commands, parameters, roles, concepts, and devices not in the cell."""
    check_terms(goal, knowledge.taxonomy, knowledge.processes_by_id)
    for item in goal.achieve:
        for d in item.bind.values():
            _device(d, cell, goal.file, item.line)
    for d in goal.end:
        _device(d, cell, goal.file, goal.lines.get("end"))


def _device(device: str, cell: Cell, path: str, line: int | None) -> None:
    ids = [d.id for d in cell.devices]
    if device not in ids:
        raise DescriptionError(f"the cell has no device {device!r}{did_you_mean(device, ids)}", path, line)


# ------------------------------------------------------------------ the search


def goal_facts(goal: Goal, processes: Sequence[ProcessDescription], taxonomy: Taxonomy) -> list[Atom]:
    """What plan.lp reads of a goal and of the processes' data flow."""
    out: list[Atom] = []
    for g, item in enumerate(goal.achieve, start=1):
        out.append(ps.Need(g, item.command))
        out += [ps.Fixed(g, n) for n in sorted(item.params)]
        out += [ps.Pinned(g, r, d) for r, d in sorted(item.bind.items())]
    for p in processes:
        out += [ps.Feeds(p.id, n, q, ty) for n, (q, ty) in feeding(p).items()]
        out += [ps.Gives(p.id, o.name, o.quantity, o.datatype) for o in p.outputs]
        if goal.until is not None and falling_under(goal.until, p.outcomes, taxonomy):
            out.append(ps.Reports(p.id))
    if goal.until is not None:
        out.append(ps.Looping())
    out += [ps.EndState(d, k) for d, k in sorted(goal.end.items())]
    return out


def feeding(process: ProcessDescription) -> dict[str, tuple[str, str]]:
    """The parameters an earlier output may feed, with their (quantity, datatype): of those with one quantity and
    datatype, the first the General Process State Chart sends (role by role, along each region; those it does not
    send after, by name). Of a pick's two poses, the one it moves to first."""
    sent = [n for r in process.roles for state in r.region for n in state.params]
    rank = {n: i for i, n in reversed(list(enumerate(sent)))}
    first: dict[tuple[str, str], str] = {}
    for par in sorted(process.parameters, key=lambda par: (rank.get(par.name, len(rank)), par.name)):
        first.setdefault((par.quantity, par.datatype), par.name)
    return {n: k for k, n in first.items()}


def _search(goal: Goal, cell: Cell, knowledge: Knowledge, max_steps: int) -> Model | tuple[str, ...]:
    """The best plan's model, or why there is none."""
    why = _cannot(goal, cell, knowledge)
    if why:
        return why
    book = fact_book(knowledge)
    facts = cell_program(book, cell) + program(goal_facts(goal, knowledge.processes, knowledge.taxonomy))
    best: tuple[tuple[int, ...], Model] | None = None
    last = max_steps
    for t, model in solver.grow(solver.PLAN, facts, range(1, max_steps + 1)):
        if model is not None:
            key = (len(model[ps.Blind]) + sum(w.h == t for w in model[ps.Wasted]), t, len(model[ps.Bound]))
            if best is None or key < best[0]:
                best = (key, model)
            last = min(last, t + LOOK_FURTHER) if best[0][0] else t
        if t >= last:
            break
    if best is None:
        return (f"no plan of at most {max_steps} steps reaches the goal from the devices' states",)
    return best[1]


def _fastest(goal: Goal, cell: Cell, knowledge: Knowledge, max_steps: int, source: str) -> Plan | tuple[str, ...]:
    """The plan of least estimated cycle time among the best of each horizon searched, or why there is none."""
    from plugnproduce.timing.tasks import task_cycle_time

    why = _cannot(goal, cell, knowledge)
    if why:
        return why
    by_id = knowledge.processes_by_id
    facts = cell_program(fact_book(knowledge), cell) + program(goal_facts(goal, knowledge.processes,
                                                                           knowledge.taxonomy))
    best: tuple[tuple[float, ...], Plan] | None = None
    last = max_steps
    for t, models in solver.grow_optima(solver.PLAN, facts, range(1, max_steps + 1), MOST_PLANS):
        for model in models:
            written = _written(goal, model, by_id, source)
            estimate = task_cycle_time(written.task, cell, knowledge)
            seconds = estimate.total if estimate is not None else float("inf")
            key = (len(model[ps.Blind]) + sum(w.h == t for w in model[ps.Wasted]), seconds, t, len(model[ps.Bound]))
            if best is None or key < best[0]:
                best = (key, dataclasses.replace(written, cycle_time=estimate.total if estimate else None))
        if models:
            last = min(last, t + LOOK_FURTHER)
        if t >= last:
            break
    if best is None:
        return (f"no plan of at most {max_steps} steps reaches the goal from the devices' states",)
    return best[1]


def _cannot(goal: Goal, cell: Cell, knowledge: Knowledge) -> tuple[str, ...]:
    """Why no plan can exist, whatever its length: commands the cell does not offer, an outcome none reports."""
    caps = capabilities(cell, knowledge)
    offered = {o.command for o in caps.offered}
    why = [f"{n.command} is not offered: {r.plain}" for n in caps.not_offered
           if n.command in {i.command for i in goal.achieve} for r in n.reasons]
    if goal.until is not None and not any(falling_under(goal.until, p.outcomes, knowledge.taxonomy)
                                          for p in knowledge.processes if p.id in offered):
        why.append(f"no command the cell offers reports {local_name(goal.until)}")
    return tuple(why)


# ------------------------------------------------------------------ the plan as a task file


def _written(goal: Goal, model: Model, processes: Mapping[str, ProcessDescription], source: str) -> Plan:
    acts = {a.t: a.p for a in model[ps.Act]}
    binds: dict[int, dict[str, str]] = defaultdict(dict)
    for b in model[ps.Bound]:
        binds[b.t][b.r] = b.d
    items = {d.t: goal.achieve[d.g - 1] for d in model[ps.Does]}
    links: dict[int, dict[str, tuple[int, str]]] = defaultdict(dict)
    for link in model[ps.PlanLink]:
        links[link.t][link.n] = (link.t0, link.o)
    names = _names(acts, {t0 for ls in links.values() for t0, _ in ls.values()})
    entries = []
    for t in sorted(acts):
        process = processes[acts[t]]
        entry: dict[str, object] = {"name": names[t]} if t in names else {}
        entry["command"] = process.id
        entry["bind"] = {r.name: binds[t][r.name] for r in process.roles}
        fixed = items[t].params if t in items else {}
        params: dict[str, object] = {}
        for par in process.parameters:
            if par.name in fixed:
                params[par.name] = fixed[par.name]
            elif par.name in links[t]:
                t0, output = links[t][par.name]
                params[par.name] = {"from": names[t0], "output": output}
        if params:
            entry["params"] = params
        entries.append(entry)
    doc: dict[str, object] = {"task": goal.name,
                              "description": goal.description or f"Planned from the goal {goal.name}."}
    if goal.until is not None:
        doc["steps"] = [{"loop": {"until": concept_value(goal.until), "max": goal.max, "steps": entries}}]
    else:
        doc["steps"] = entries
    task = parse_task(yaml.dump(doc, Dumper=PlainDumper, sort_keys=False).encode("utf-8"), source)
    text = f"# Planned by pnp plan from the goal {goal.name} ({len(acts)} steps).\n" + task_to_yaml(task)
    blind = tuple(sorted((b.t, b.n) for b in model[ps.Blind]))
    wasted = tuple(sorted((w.t, w.o) for w in model[ps.Wasted] if w.h == len(acts)))
    return Plan(goal, text, task, len(acts), blind, wasted)


def _names(acts: dict[int, str], sources: set[int]) -> dict[int, str]:
    """A name for each step whose outputs later steps take: its command, numbered when it runs twice."""
    out: dict[int, str] = {}
    for t in sorted(sources):
        base = acts[t].replace("-", "_")
        if not base[:1].isalpha():
            base = "step_" + base
        name, k = base, 1
        while name in out.values():
            k += 1
            name = f"{base}_{k}"
        out[t] = name
    return out
