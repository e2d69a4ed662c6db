"""The plausibility check of a task in a cell, and why a step is (not) plausible (resolve.lp, chain.lp, params.lp)."""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, Task, Where
from plugnproduce.description.outcomes import flow_findings
from plugnproduce.errors import UnknownName
from plugnproduce.reasoning.asp import render, solver
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.facts import fact_book, task_facts
from plugnproduce.reasoning.asp.results import CheckResult, Problem, Reason, StepCheck, StepExplanation
from plugnproduce.reasoning.asp.terms import Model, program
from plugnproduce.reasoning.checks.accepts import not_accepted, not_taken
from plugnproduce.reasoning.checks.branches import (
    MAX_PATH_STEPS,
    MAX_PATHS,
    check_paths,
    join_problems,
    on_a_path,
    renumbered,
    renumbered_text,
    task_paths,
)
from plugnproduce.reasoning.checks.contracts import beyond_limits, normalised
from plugnproduce.reasoning.checks.controlflow import loop_problems, on_path
from plugnproduce.reasoning.checks.dataflow import link_problems, unreported
from plugnproduce.reasoning.checks.offers import CELL, cell_program, context

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

TASK = "task"
"""The name a single task gets in ASP."""


def _problems(model: Model, ctx: render.Context) -> list[Problem]:
    left = {(a.i, a.d): a.j for a in model[s.LeftBy]}
    out = [render.wrong_state(ctx, a, left.get((a.i, a.d))) for a in model[s.WrongState]]
    out += [render.stuck(ctx, a) for a in model[s.Stuck]]
    out += [render.unknown_command(ctx, a) for a in model[s.UnknownCommand]]
    missing = tuple(sorted(model[s.MissingArg], key=lambda m: (m.d, m.req, m.q)))
    out += [render.binding_problem(ctx, "no_device", a.i, a.r, [], missing) for a in model[s.NoDevice]]
    ambiguous: dict[tuple[int, str], list[str]] = defaultdict(list)
    for b in model[s.Ambiguous]:
        ambiguous[(b.i, b.r)].append(b.d)
    out += [render.binding_problem(ctx, "ambiguous", i, r, ds) for (i, r), ds in ambiguous.items()]
    out += [render.binding_problem(ctx, "absent", a.i, a.r, [a.d]) for a in model[s.Absent]]
    out += [render.binding_problem(ctx, "cannot_play", a.i, a.r, [a.d], missing) for a in model[s.CannotPlay]]
    out += [render.binding_problem(ctx, "unknown_role", a.i, a.r, []) for a in model[s.UnknownRole]]
    values: list[s.BadType | s.TooLow | s.TooHigh | s.UnknownParam] = [
        *model[s.BadType], *model[s.TooLow], *model[s.TooHigh], *model[s.UnknownParam]]
    out += [render.parameter_problem(ctx, a) for a in values]
    return sorted(out, key=lambda p: (p.step, p.kind, p.role or "", p.parameter or "", p.device or ""))


def _steps(model: Model, task: Task) -> tuple[tuple[StepCheck, ...], dict[str, str]]:
    bound: dict[int, dict[str, str]] = defaultdict(dict)
    for b in model[s.Bound]:
        bound[b.i][b.r] = b.d
    states: dict[int, dict[str, str]] = defaultdict(dict)
    for a in model[s.At]:
        states[a.i][a.d] = a.x
    steps = tuple(StepCheck(st.index, st.command, dict(sorted(bound[st.index].items())),
                            dict(sorted(states[st.index].items()))) for st in task.steps)
    return steps, dict(sorted(states[len(task.steps) + 1].items()))


def run_check(task: Task, cell: Cell, knowledge: Knowledge) -> tuple[Model, render.Context]:
    """The check's model and the context to render it."""
    book = fact_book(knowledge)
    facts = cell_program(book, cell) + program(task_facts(task, TASK)) + program([s.Check(CELL, TASK)])
    return solver.solve(solver.CHECK, facts), context(book, cell, task=task)


def check(task: Task, cell: Cell, knowledge: Knowledge) -> CheckResult:
    """Whether ``task`` is plausible in ``cell``; per step its bindings, device states and problems.

    A task with loops is checked on every path: see :mod:`plugnproduce.reasoning.checks.controlflow`.
    Quantities written with a unit are read in their parameters' units first; every value a device
    is sent must keep that device's contract (:mod:`plugnproduce.reasoning.checks.contracts`).
    """
    if task.branches:
        return _branched(task, cell, knowledge)
    task, unreadable = normalised(task, knowledge.processes)
    model, ctx = run_check(task, cell, knowledge)
    steps, final = _steps(model, task)
    parameters = {p.id: {x.name: x for x in p.parameters} for p in knowledge.processes}
    lost = list(not_accepted(task, cell, steps, parameters, knowledge.taxonomy))
    lost += not_taken(task, cell, steps, knowledge.processes_by_id, knowledge.taxonomy)
    lost += link_problems(task, knowledge)
    lost += unreported(task, cell, steps, knowledge.processes_by_id)
    lost += unreadable + list(beyond_limits(task, cell, steps, knowledge)) + flow_problems(task, knowledge)
    problems = [on_path(p, task) for p in _problems(model, ctx) + lost]
    plausible = any(a.c == CELL and a.t == TASK for a in model[s.Plausible]) and not problems
    result = CheckResult(task.name, cell.name, plausible, (), steps, final)
    if task.loops:
        problems += loop_problems(task, result, knowledge, lambda straight: check(straight, cell, knowledge))
    problems = sorted(problems, key=lambda p: (p.step, p.kind, p.parameter or ""))
    return dataclasses.replace(result, plausible=result.plausible and not problems, problems=tuple(problems))


def flow_problems(task: Task, knowledge: Knowledge) -> list[Problem]:
    """Branches and loops on outcomes that cannot work (:mod:`plugnproduce.description.outcomes`), at their lines."""
    out = []
    for f in flow_findings(task, knowledge.processes_by_id, knowledge.taxonomy):
        where = Where(task.file, f.line)
        out.append(Problem(f.step, f.command, "bad_flow", Reason("bad_flow", f.text, (), (where,)), where))
    return out


def _branched(task: Task, cell: Cell, knowledge: Knowledge) -> CheckResult:
    """The check of a task with branches: each of its paths (:mod:`plugnproduce.reasoning.checks.branches`)."""
    paths = task_paths(task, knowledge)
    if len(paths) > MAX_PATHS or sum(len(p.positions) for p in paths) > MAX_PATH_STEPS:
        where = Where(task.file, paths[-1].branch.line if paths[-1].branch else None)
        text = (f"the task has more paths through its branches than are checked: at most {MAX_PATHS} paths of "
                f"{MAX_PATH_STEPS} steps in all")
        problem = Problem(1, task.steps[0].command, "too_many_paths", Reason("too_many_paths", text, (), (where,)),
                          where)
        return CheckResult(task.name, cell.name, False, (problem,), ())
    checks = check_paths(task, paths, lambda straight: check(straight, cell, knowledge))
    steps = tuple(checks.steps.get(i, StepCheck(i, s.command, {}, {})) for i, s in enumerate(task.steps, start=1))
    result = CheckResult(task.name, cell.name, True, (), steps, checks.final(paths[0]))
    problems = [*checks.problems.values(), *flow_problems(task, knowledge)]
    problems += [on_path(p, task) for p in link_problems(task, knowledge)]
    problems += [on_path(p, task) for p in unreported(task, cell, steps, knowledge.processes_by_id)]
    problems += join_problems(task, checks, knowledge)
    problems += loop_problems(task, result, knowledge, lambda t: check(t, cell, knowledge), paths)
    problems = sorted(problems, key=lambda p: (p.step, p.kind, p.parameter or ""))
    return dataclasses.replace(result, plausible=not problems, problems=tuple(problems))


def explain_step(task: Task, cell: Cell, n: int, knowledge: Knowledge) -> StepExplanation:
    """Why step ``n`` (1-based) is (not) plausible: each device it uses, its state and what the step needs."""
    if not 1 <= n <= len(task.steps):
        raise UnknownName("step", n, detail=f"the task has steps 1 to {len(task.steps)}")
    if task.branches:  # along a path that runs the step, so that its states are the ones it starts from
        straight, positions = on_a_path(task, n, knowledge)
        ex = explain_step(straight, cell, positions.index(n) + 1, knowledge)
        states = tuple(dataclasses.replace(r, text=renumbered_text(r.text, positions)) for r in ex.states)
        return dataclasses.replace(ex, step=n, states=states,
                                   problems=tuple(renumbered(p, positions) for p in ex.problems))
    task, _ = normalised(task, knowledge.processes)
    model, ctx = run_check(task, cell, knowledge)
    left = {(a.i, a.d): a.j for a in model[s.LeftBy]}
    at = {(a.i, a.d): a.x for a in model[s.At]}
    bound = sorted((b.r, b.d) for b in model[s.Bound] if b.i == n)
    states = tuple(render.device_state(ctx, n, r, d, at[(n, d)], left.get((n, d))) for r, d in bound if (n, d) in at)
    problems = tuple(p for p in _problems(model, ctx) if p.step == n)
    return StepExplanation(n, task.steps[n - 1].command, not problems, states, problems)
