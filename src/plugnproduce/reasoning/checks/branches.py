"""Branches of a task: every path through them is checked, and every path must join alike.

The task's steps hold every branch flattened (:mod:`plugnproduce.description.flow`), so
the sequence as written is no path once a step has two branches. A **path** chooses, at
each step with branches, the branch the step's outcome takes, or none (when some outcome
the step can go on with takes no branch; an outcome that ends the step's loop
(``until``) never reaches its branches). The check runs on the **default path** (no
branch where an outcome takes none, else the first reachable one) and on one path per
other branch (taking it and the branches it lies in), so every step is checked
from the device states it really starts from; at most :data:`MAX_PATHS` paths of
:data:`MAX_PATH_STEPS` steps in all.

The steps after a step's branches are generated once, for one set of device states:
every way on from the step (each reachable branch, and going on without one) must leave
every device in the same state. A branch that does not is refused at its line, naming
its path (``branch NoPartFound at step 3``); a step after it that cannot start from what
the branch left is refused at that step, named ``after branch NoPartFound at step 3``.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable, Iterator
from dataclasses import field
from typing import TYPE_CHECKING

from plugnproduce.deferred import dataclass
from plugnproduce.description.flow import Branch
from plugnproduce.description.model import Task, Where
from plugnproduce.description.outcomes import branch_of, ending_loop
from plugnproduce.reasoning.asp.results import CheckResult, Problem, Reason, StepCheck

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

MAX_PATHS = 100
"""Most paths a task's check runs (one per branch, and the default one)."""
MAX_PATH_STEPS = 200_000
"""Most steps the paths of one task's check hold together (a 10,000-step task: 20 paths)."""


@dataclass(frozen=True)
class Path:
    """One path through a task's branches: the step positions it runs, in order."""

    branch: Branch | None
    """The branch the path was chosen to take (None: the default path)."""
    positions: tuple[int, ...]

    def label(self, task: Task, index: int) -> str | None:
        """How a finding at position ``index`` on this path names its path."""
        named = task.path(index)
        if self.branch is None or self.branch.holds(index) or index < self.branch.step:
            return named
        after = f"after {self.branch.path}"
        return f"{named}, {after}" if named else after


def ways_on(task: Task, index: int, knowledge: Knowledge) -> tuple[tuple[Branch, ...], bool]:
    """The branches of the step at ``index`` that an outcome going on in the task takes, and whether the
    task may also go on without one."""
    process, taxonomy = knowledge.processes_by_id.get(task.steps[index - 1].command), knowledge.taxonomy
    siblings = task.branches_of(index)
    if process is None or not process.outcomes:
        return (), True
    goes_on = [o for o in process.outcomes if ending_loop(task, index, o, taxonomy) is None]
    taken = [branch_of(o, siblings, taxonomy) for o in goes_on]
    return tuple(b for b in siblings if b in taken), None in taken or not goes_on


def _positions(task: Task, choices: dict[int, Branch | None]) -> tuple[int, ...]:
    """The positions a path runs: every branch not chosen at its step is skipped (with all it holds)."""
    skip = [0] * (len(task.steps) + 2)
    for b in task.branches:
        if choices.get(b.step) != b:
            skip[b.first] += 1
            skip[b.last + 1] -= 1
    out, depth = [], 0
    for i in range(1, len(task.steps) + 1):
        depth += skip[i]
        if depth == 0:
            out.append(i)
    return tuple(out)


def task_paths(task: Task, knowledge: Knowledge) -> list[Path]:
    """The default path, then one path for each branch it does not take (a branch no outcome takes too:
    it is refused on its own, and its steps still get their bindings)."""
    default: dict[int, Branch | None] = {}
    for index in sorted({b.step for b in task.branches}):
        reachable, without = ways_on(task, index, knowledge)
        default[index] = None if without or not reachable else reachable[0]
    paths = [Path(None, _positions(task, default))]
    on_default = set(paths[0].positions)
    for b in task.branches:
        if b.first in on_default:
            continue
        if len(paths) > MAX_PATHS or sum(len(p.positions) for p in paths) > MAX_PATH_STEPS:
            break  # more than can be checked: the check refuses the task
        choices = dict(default)
        choices.update({a.step: a for a in task.branches if a.holds(b.step)})
        choices[b.step] = b
        paths.append(Path(b, _positions(task, choices)))
    return paths


def covering(paths: list[Path], index: int) -> Path:
    """The first path that runs position ``index`` (the default one where it does)."""
    return next((p for p in paths if index in p.positions), paths[0])


def join_problems(task: Task, checks: PathChecks, knowledge: Knowledge) -> Iterator[Problem]:
    """A reachable branch that leaves a device otherwise than the other ways on from its step."""
    paths = checks.paths
    for index in sorted({b.step for b in task.branches}):
        if not any(index in p.positions for p in paths):
            continue
        reachable, without = ways_on(task, index, knowledge)
        if not reachable:
            continue
        block = max(b.last for b in task.branches_of(index))
        ways = [(covering(paths, b.first), b) for b in reachable]
        base_path, base = (covering(paths, index), None) if without else ways[0]
        before = checks.after(base_path, index if base is None else block)
        for path, b in ways:
            if b == base:
                continue
            states = checks.after(path, block)
            yield from _unlike(task, b, base, states, before)


def _unlike(task: Task, b: Branch, base: Branch | None, states: dict[str, str],
            before: dict[str, str]) -> Iterator[Problem]:
    other = "going on without a branch" if base is None else base.path
    for device in sorted(set(states) & set(before)):
        if states[device] == before[device]:
            continue
        text = (f"{b.path}: device {device} is left in state '{states[device]}', but {other} leaves it in "
                f"'{before[device]}'; every way on from step {b.step} must leave each device in one state, "
                "as the steps after it start from it")
        where = Where(task.file, b.line)
        yield Problem(b.first, task.steps[b.first - 1].command, "branch_join",
                      Reason("branch_join", text, (), (where,)), where, device=device, state=states[device])


Check = Callable[[Task], CheckResult]
"""The check of a straight task (no loops, no branches) in the same cell."""


def _straight(task: Task, positions: tuple[int, ...]) -> Task:
    """The path as a task of its own: its steps in order, numbered from 1."""
    steps = tuple(dataclasses.replace(task.steps[p - 1], index=i + 1) for i, p in enumerate(positions))
    return dataclasses.replace(task, steps=steps, loops=(), branches=(), repeat=1)


@dataclass
class PathChecks:
    """What the checks of a task's paths found: each position's step as its first path saw it."""

    paths: list[Path]
    steps: dict[int, StepCheck] = field(default_factory=dict)
    finals: dict[tuple[int, ...], dict[str, str]] = field(default_factory=dict)
    states: dict[tuple[int, ...], dict[int, dict[str, str]]] = field(default_factory=dict)
    """Per path, the device states before each of its positions."""
    problems: dict[tuple[object, ...], Problem] = field(default_factory=dict)

    def final(self, path: Path) -> dict[str, str]:
        """The device states ``path`` leaves at its end."""
        return self.finals[path.positions]

    def after(self, path: Path, last: int) -> dict[str, str]:
        """Device states on ``path`` once position ``last`` (and all it holds) is done."""
        nxt = next((i for i in path.positions if i > last), None)
        return self.states[path.positions].get(nxt, {}) if nxt is not None else self.finals[path.positions]


def check_paths(task: Task, paths: list[Path], check: Check) -> PathChecks:
    """Check each path as a straight task; its problems (but links: the task's own check) at their positions."""
    out = PathChecks(paths)
    for path in paths:
        result = check(_straight(task, path.positions))
        out.finals[path.positions] = result.final_states
        out.states[path.positions] = {}
        for position, step in zip(path.positions, result.steps, strict=False):
            out.steps.setdefault(position, dataclasses.replace(step, index=position))
            out.states[path.positions][position] = step.states
        for p in result.problems:
            if p.kind == "bad_link":
                continue
            moved = renumbered(p, path.positions)
            key = (moved.step, p.kind, p.role, p.device, p.parameter)
            if key not in out.problems:
                label = path.label(task, moved.step)
                out.problems[key] = named(moved, label) if label else moved
    return out


_STEP = re.compile(r"\bstep (\d+)\b")


def renumbered_text(text: str, positions: tuple[int, ...]) -> str:
    """A straight path's sentence with its step numbers the task's positions."""
    def position(m: re.Match[str]) -> str:
        n = int(m.group(1))
        return f"step {positions[n - 1]}" if 1 <= n <= len(positions) else m.group(0)

    return _STEP.sub(position, text)


def on_a_path(task: Task, index: int, knowledge: Knowledge,
              check: Check | None = None) -> tuple[Task, tuple[int, ...]]:
    """A path through the task's branches that runs position ``index``, as a straight task, and its positions:
    the first on which ``check`` finds a problem at the step (the first that runs it, without ``check``)."""
    paths = [p for p in task_paths(task, knowledge) if index in p.positions]
    for path in paths if check is not None else ():
        straight = _straight(task, path.positions)
        assert check is not None
        if any(p.step == path.positions.index(index) + 1 for p in check(straight).problems):
            return straight, path.positions
    path = paths[0] if paths else Path(None, tuple(range(1, len(task.steps) + 1)))
    return _straight(task, path.positions), path.positions


def renumbered(problem: Problem, positions: tuple[int, ...]) -> Problem:
    """A straight path's problem with its step numbers (in its text too) the task's positions."""
    reason = dataclasses.replace(problem.reason, text=renumbered_text(problem.reason.text, positions))
    step = positions[problem.step - 1] if 1 <= problem.step <= len(positions) else positions[-1]
    return dataclasses.replace(problem, step=step, reason=reason)


def named(problem: Problem, path: str) -> Problem:
    """The problem with its path named in its text."""
    reason = dataclasses.replace(problem.reason, text=f"{path}: {problem.reason.text}")
    return dataclasses.replace(problem, reason=reason)
