"""Control flow of a task: every path through its loops must be plausible.

The task's steps hold a loop's body twice (its first iteration, then the iterations after
it), so the chained check already covers iteration 1, iteration 2 and the steps after
the loop. This module adds what a straight line cannot show:

- the **fixpoint**: an iteration must leave every device in the state the iteration
  before it left it in, so that every later iteration starts as the second one did (a loop
  of at most two iterations has no later one);
- the **exits**: a loop ends as soon as a step of its body ends with the loop's
  ``until`` outcome, so the steps after the loop must also be plausible from the states
  that step leaves, in the first iteration and in the later ones.

Problems name their path: ``loop iteration 1``, ``loop iteration 2 and later``,
``loop ended on BinEmpty at step N``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from plugnproduce.description.model import Loop, Task, Where
from plugnproduce.description.outcomes import loop_ending
from plugnproduce.ontology.iris import local_name
from plugnproduce.reasoning.asp.results import CheckResult, Problem, Reason
from plugnproduce.reasoning.checks.branches import Path, covering, renumbered

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

Check = Callable[[Task], CheckResult]
"""The chained check of a straight task (no loops) in the same cell."""


def on_path(problem: Problem, task: Task) -> Problem:
    """The problem with the path its step lies on (loop iteration, branches) named in its text."""
    path = task.path(problem.step)
    return _named(problem, path) if path else problem


def _named(problem: Problem, path: str) -> Problem:
    reason = dataclasses.replace(problem.reason, text=f"{path}: {problem.reason.text}")
    return dataclasses.replace(problem, reason=reason)


def loop_problems(task: Task, result: CheckResult, knowledge: Knowledge,
                  check: Check, paths: list[Path] | None = None) -> Iterator[Problem]:
    """Problems of the task's loops: an iteration that does not return the devices, an exit that strands them.

    ``paths`` are the task's paths through its branches (none: the steps in order are its one path).
    """
    every = paths or [Path(None, tuple(range(1, len(task.steps) + 1)))]
    for loop in task.loops:
        if loop.max is None or loop.max > 2:  # a third iteration would start where the second left the devices
            yield from _fixpoint(task, loop, result)
        if loop.until is not None:
            yield from _exits(task, loop, knowledge, check, every)


def _states_before(result: CheckResult, index: int) -> dict[str, str]:
    """Device states when step position ``index`` starts (the final states after the last step)."""
    return result.steps[index - 1].states if index <= len(result.steps) else result.final_states


def _fixpoint(task: Task, loop: Loop, result: CheckResult) -> Iterator[Problem]:
    before, after = _states_before(result, loop.first), _states_before(result, loop.last + 1)
    first = task.steps[loop.first - 1]
    for device in sorted(before):
        if device in after and after[device] != before[device]:
            text = (f"loop iteration: device {device} ends an iteration in state '{after[device]}', but the "
                    f"iteration before left it in '{before[device]}'; each iteration must leave every device "
                    "as it found it")
            where = Where(task.file, first.line)  # the iteration's first step, as for the step's other findings
            rests_on = (where, Where(task.file, loop.line))
            yield Problem(loop.first, first.command, "loop_fixpoint", Reason("loop_fixpoint", text, (), rests_on),
                          where, device=device, state=after[device])


def _exits(task: Task, loop: Loop, knowledge: Knowledge, check: Check,
           paths: list[Path]) -> Iterator[Problem]:
    """Check the steps after the loop, on each path through them, from where each step that can end the loop
    leaves the devices."""
    rests: dict[tuple[int, ...], Path] = {}
    for path in paths:  # a path's rest: its positions after the loop (the first path of each rest names it)
        rests.setdefault(tuple(i for i in path.positions if i > loop.last), path)
    rests.pop((), None)
    if not rests:
        return
    assert loop.until is not None
    until = loop.until
    for step in task.steps[loop.entry - 1 : loop.last]:
        process = knowledge.processes_by_id.get(step.command)
        if process is None or not any(loop_ending(task, step.index, o, knowledge.taxonomy) == loop
                                      for o in process.outcomes):
            continue
        head = tuple(i for i in covering(paths, step.index).positions if i <= step.index)
        label = f"loop ended on {local_name(until)} at step {step.index} ({task.path(step.index)})"
        seen: set[tuple[int, str, str]] = set()  # a problem of this exit found again on another path
        for rest, path in rests.items():
            yield from _exit_problems(task, loop, check, head + rest, len(head), path, label, seen)


def _exit_problems(task: Task, loop: Loop, check: Check, route: tuple[int, ...], ended: int, path: Path,
                   label: str, seen: set[tuple[int, str, str]]) -> Iterator[Problem]:
    """The problems of the steps after the loop on ``route``, the loop ended at its position ``ended``; each once."""
    straight = dataclasses.replace(task, steps=tuple(dataclasses.replace(task.steps[p - 1], index=i + 1)
                                                     for i, p in enumerate(route)),
                                   loops=(), branches=(), repeat=1)
    for problem in check(straight).problems:
        if problem.step <= ended or problem.kind == "bad_link":
            continue
        found = renumbered(problem, route)
        key = (found.step, found.kind, found.text)
        if key in seen:
            continue
        seen.add(key)
        on = path.label(task, found.step) if path.branch is not None and path.branch.step > loop.last else None
        yield _named(found, f"{label}, {on}" if on else label)
