"""A task checked again from the check of a task it was made from: only the steps that changed, or that find
a device in another state than before, are checked again (a repaired long task costs its edits, not its length).

The check of a straight task (no loops, no branches, one round, no step taking another's output) is a fold over
its steps: a step's bindings follow from the step and the cell alone, and the states it leaves its devices in
and its problems from the step, the cell and the states its bound devices start in (chain.lp, resolve.lp,
params.lp; the values against the devices' contracts, :mod:`.contracts`, need only the step and its bindings,
and whether a value is taken on its device's route, :mod:`.accepts`, the state that route starts from); a
device no step uses keeps its state. So each problem-free step of the earlier check
is a known move: the same step (command, bindings, values) starting from the same states of the same devices
is problem-free again and leaves them as it did. :func:`recheck` follows the new task through those moves
and checks, for real and with the states found there, every run of steps it has not seen
(:func:`~.plausibility.check` of the run alone, its devices starting in those states). It answers only when
every step is problem-free, which is the answer the whole check gives; anything else (a problem anywhere, a
task of another shape) is None, and the caller checks the whole task, which words the problems exactly.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Hashable, Sequence
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, Step, Task
from plugnproduce.reasoning.asp.results import CheckResult, StepCheck
from plugnproduce.reasoning.checks.plausibility import check

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

States = tuple[tuple[str, str | None], ...]
"""Some devices' states, by device."""


def _sig(step: Step) -> Hashable:
    return step.command, tuple(sorted(step.bind.items())), repr(sorted(step.params.items()))


def straight(task: Task) -> bool:
    """Whether the task's check is a fold over its steps (see the module's docstring)."""
    return (not task.loops and not task.branches and task.repeat == 1 and bool(task.steps)
            and not any(st.links() for st in task.steps))


class Moves:
    """The problem-free steps of checks in one cell: each step's bindings, and what it does from which states."""

    def __init__(self, cell: Cell, knowledge: Knowledge, task: Task, result: CheckResult):
        """The moves of ``result``, the check of ``task`` in ``cell``."""
        self.cell, self.knowledge = cell, knowledge
        self.initial = dict(result.steps[0].states) if result.steps else {}
        """The devices' states before the first step."""
        self.bindings: dict[Hashable, dict[str, str]] = {}
        self.moves: dict[tuple[Hashable, States], States] = {}
        self.checked_again = 0
        """How many steps :meth:`checked` has checked (the rest followed known moves)."""
        if straight(task):
            self.learn(task, result)

    def learn(self, task: Task, result: CheckResult) -> None:
        """The moves of a check's steps that have no problem."""
        bad = {p.step for p in result.problems}
        after = [*(st.states for st in result.steps[1:]), result.final_states]
        for step, seen, nxt in zip(task.steps, result.steps, after, strict=False):
            if step.index in bad:
                continue
            sig, devices = _sig(step), sorted(set(seen.bindings.values()))
            self.bindings[sig] = dict(seen.bindings)
            self.moves[(sig, tuple((d, seen.states.get(d)) for d in devices))] = tuple(
                (d, nxt.get(d)) for d in devices)

    def move(self, step: Step, states: dict[str, str]) -> tuple[dict[str, str], States] | None:
        """The bindings of a step seen before and what it leaves its devices in, if it started from these states."""
        sig = _sig(step)
        bound = self.bindings.get(sig)
        if bound is None:
            return None
        left = self.moves.get((sig, tuple((d, states.get(d)) for d in sorted(set(bound.values())))))
        return None if left is None else (bound, left)

    def checked(self, steps: Sequence[Step], states: dict[str, str]) -> CheckResult | None:
        """The check of a run of steps alone, its devices starting in ``states`` (None: a problem); learnt."""
        devices = tuple(dataclasses.replace(d, initial=states.get(d.id, d.initial)) for d in self.cell.devices)
        run = Task("run", tuple(dataclasses.replace(st, index=k) for k, st in enumerate(steps, start=1)), "run")
        result = check(run, dataclasses.replace(self.cell, devices=devices), self.knowledge)
        self.checked_again += len(steps)
        if not result.plausible:
            return None
        self.learn(run, result)
        return result


def recheck(task: Task, moves: Moves) -> CheckResult | None:
    """The check of ``task`` in the cell of ``moves`` when it is plausible (None: check the whole task)."""
    if not straight(task) or not moves.moves:
        return None
    states = dict(moves.initial)
    out: list[StepCheck] = []
    i = 0
    while i < len(task.steps):
        known = moves.move(task.steps[i], states)
        if known is not None:
            bound, left = known
            out.append(StepCheck(i + 1, task.steps[i].command, dict(sorted(bound.items())),
                                 dict(sorted(states.items()))))
            _apply(states, left)
            i += 1
            continue
        end = i + 1  # the run of steps never seen, checked together
        while end < len(task.steps) and _sig(task.steps[end]) not in moves.bindings:
            end += 1
        result = moves.checked(task.steps[i:end], states)
        if result is None:
            return None
        out += [dataclasses.replace(st, index=i + k) for k, st in enumerate(result.steps, start=1)]
        states = dict(result.final_states)
        i = end
    return CheckResult(task.name, moves.cell.name, True, (), tuple(out), dict(sorted(states.items())))


def _apply(states: dict[str, str], left: States) -> None:
    for d, x in left:
        if x is None:
            states.pop(d, None)
        else:
            states[d] = x
