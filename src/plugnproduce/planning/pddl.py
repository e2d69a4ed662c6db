"""A goal as PDDL (a domain and a problem), for planners the project did not write (Fast Downward).

The actions are ground: one per process command, role binding (a device of its own per role), start
states of the bound devices, the goal item it fulfils (if any) and, for each value the cell could
measure, whether an earlier output feeds it. Device states are propositions (``at_D_X``), data flow
is ``have_Q`` (an output of quantity Q was produced) and ``fresh_Q`` (and nothing has taken it yet).
Action costs say what ``pnp plan`` optimises, in order: values left to defaults although measurable
and measured values no step takes (:data:`PENALTY` each), then steps (:data:`STEP`), then roles
(1 each). So an optimal PDDL planner's plan costs what the best plan costs. A goal with ``until``
has no PDDL form (PDDL plans have no loops) and is refused.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

from plugnproduce.description.goalfile import Goal
from plugnproduce.description.model import Cell, ProcessDescription
from plugnproduce.description.paths import in_concept
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.planning.planner import check_goal, feeding
from plugnproduce.reasoning.asp.facts import effects
from plugnproduce.reasoning.asp.schema import Leaves
from plugnproduce.reasoning.checks.offers import capabilities

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

PENALTY = 1000
"""Cost of a value left to its default although the cell could measure it, or of a measured value no step takes."""
STEP = 10
"""Cost of a step (each role it binds adds 1)."""


@dataclass(frozen=True)
class Action:
    """One ground action: its name, preconditions, effects and cost; ``step`` says what it stands for."""

    name: str
    pre: tuple[str, ...]
    add: tuple[str, ...]
    delete: tuple[str, ...]
    cost: int


def _id(*parts: str) -> str:
    return re.sub(r"[^a-z0-9_-]+", "_", "_".join(parts).lower()).strip("_-") or "x"


def actions(goal: Goal, cell: Cell, knowledge: Knowledge) -> list[Action]:
    """Every ground action of the goal's domain in this cell."""
    by_id, taxonomy = knowledge.processes_by_id, knowledge.taxonomy
    caps = capabilities(cell, knowledge)
    consumable = {k for o in caps.offered for k in feeding(by_id[o.command]).values()}
    measured = {(q.quantity, q.datatype) for o in caps.offered for q in by_id[o.command].outputs} & consumable
    out: list[Action] = []
    for offer in caps.offered:
        p = by_id[offer.command]
        for binding in _bindings(offer.role_devices, [r.name for r in p.roles]):
            for starts in _starts(p, binding, cell, taxonomy):
                out += _variants(goal, p, binding, starts, measured)
    return out


def _bindings(players: dict[str, tuple[str, ...]], roles: list[str]) -> Iterator[dict[str, str]]:
    for devices in itertools.product(*(players[r] for r in roles)):
        if len(set(devices)) == len(devices):
            yield dict(zip(roles, devices, strict=True))


def _starts(p: ProcessDescription, binding: dict[str, str], cell: Cell,
            taxonomy: Taxonomy) -> Iterator[dict[str, tuple[str, str]]]:
    """Per role, a start state and the state the role leaves its device in (every combination)."""
    per_role = []
    for r, d in binding.items():
        moves = [(a.x, a.y) for a in effects(cell.device(d), p, taxonomy) if isinstance(a, Leaves) and a.r == r]
        per_role.append([(r, m) for m in moves])
    for combo in itertools.product(*per_role):
        yield dict(combo)


def _variants(goal: Goal, p: ProcessDescription, binding: dict[str, str], starts: dict[str, tuple[str, str]],
              measured: set[tuple[str, str]]) -> Iterator[Action]:
    items = [None, *(g for g, item in enumerate(goal.achieve, start=1) if item.command == p.id
                     and all(binding.get(r) == d for r, d in item.bind.items()))]
    for g in items:
        fixed = goal.achieve[g - 1].params if g else {}
        open_ = [(n, k) for n, k in feeding(p).items() if n not in fixed and k in measured]
        for linked in itertools.product((True, False), repeat=len(open_)):
            pre = [f"at_{_id(binding[r], x)}" for r, (x, _) in starts.items()]
            add = [f"at_{_id(binding[r], y)}" for r, (x, y) in starts.items() if x != y]
            delete = [f"at_{_id(binding[r], x)}" for r, (x, y) in starts.items() if x != y]
            cost = STEP + len(binding)
            for (_, k), takes in zip(open_, linked, strict=True):
                if takes:
                    pre.append(f"have_{_id(*k)}")
                    delete.append(f"fresh_{_id(*k)}")
                else:
                    cost += PENALTY
            if g:
                pre.append(f"done_{g - 1}" if g > 1 else "ready")
                add.append(f"done_{g}")
            for o in p.outputs:
                k = (o.quantity, o.datatype)
                if k in measured:
                    add += [f"have_{_id(*k)}", f"fresh_{_id(*k)}"]
            name = _id(p.id, *(f"{r}-{d}-{starts[r][0]}" for r, d in binding.items()), f"g{g or 0}",
                       "".join("l" if t else "d" for t in linked))
            gone = tuple(f for f in dict.fromkeys(delete) if f not in add)
            if add or gone:  # an action that changes nothing never helps a plan
                yield Action(name, tuple(pre), tuple(dict.fromkeys(add)), gone, cost)


def export(goal: Goal, cell: Cell, knowledge: Knowledge) -> tuple[str, str]:
    """The goal as a PDDL domain and problem (ground, with action costs)."""
    if goal.until is not None:
        raise DescriptionError("a goal with 'until' plans a loop, which PDDL cannot state; export one without it",
                               goal.file, goal.lines.get("until"))
    check_goal(goal, cell, knowledge)
    acts = actions(goal, cell, knowledge)
    facts = sorted({f for a in acts for f in (*a.pre, *a.add, *a.delete)} | {"ready"}
                   | {f"done_{g}" for g in range(1, len(goal.achieve) + 1)})
    fresh = sorted(f for f in facts if f.startswith("fresh_"))
    discard = [Action(f"discard_{f}", (f,), (), (f,), PENALTY) for f in fresh]
    lines = ["(define (domain pnp-cell)",
             "  (:requirements :strips :negative-preconditions :disjunctive-preconditions :action-costs)",
             "  (:predicates " + " ".join(f"({f})" for f in facts) + ")", "  (:functions (total-cost))"]
    for a in [*acts, *discard]:
        pre = " ".join(f"({f})" for f in a.pre)
        eff = " ".join([*(f"({f})" for f in a.add), *(f"(not ({f}))" for f in a.delete),
                        f"(increase (total-cost) {a.cost})"])
        lines += [f"  (:action {a.name}", "    :parameters ()", f"    :precondition (and {pre})",
                  f"    :effect (and {eff}))"]
    domain = "\n".join([*lines, ")"]) + "\n"
    initial = ["(ready)", *(f"(at_{_id(d.id, d.initial)})" for d in cell.devices), "(= (total-cost) 0)"]
    wanted = [f"(done_{len(goal.achieve)})", *(f"(not ({f}))" for f in fresh)]
    for d, k in sorted(goal.end.items()):
        ends = [f"(at_{_id(d, s.id)})" for s in cell.device(d).states if in_concept(s, k, knowledge.taxonomy)]
        wanted.append(f"(or {' '.join(ends)})" if ends else "(not (ready))")  # no such state: unreachable
    problem = "\n".join(["(define (problem goal)", "  (:domain pnp-cell)", f"  (:init {' '.join(initial)})",
                         f"  (:goal (and {' '.join(wanted)}))", "  (:metric minimize (total-cost)))"]) + "\n"
    return domain, problem
