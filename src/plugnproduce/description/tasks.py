"""Tasks as plain data: an ordered list of process commands with their role bindings and parameter values,
some of them in loops and branches, and the links that take a value from an earlier step's output.

:mod:`plugnproduce.description.taskfile` reads and writes them; nothing here does I/O.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import field

from plugnproduce.deferred import dataclass
from plugnproduce.description.flow import Branch, Loop, enclosing, outermost_first, path_name
from plugnproduce.description.where import Where


@dataclass(frozen=True)
class Link:
    """A parameter value taken from an earlier step's output (``{from: localize, output: part_pose}``)."""

    step: str
    """The ``name:`` of the step that produces the value."""
    output: str
    offset: tuple[float, ...] | None = None
    """For a pose: added to the output, item by item (``[0, 0, 0.2, 0, 0, 0]``: 0.2 m above it)."""

    def to_plain(self) -> dict[str, object]:
        """The link as the task file writes it."""
        plain: dict[str, object] = {"from": self.step, "output": self.output}
        if self.offset is not None:
            plain["offset"] = list(self.offset)
        return plain

    def applied(self, value: object) -> object:
        """The output ``value`` with the offset added (as it is when it is no pose of the offset's length)."""
        if self.offset is None or not isinstance(value, list | tuple) or len(value) != len(self.offset) or \
                not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
            return value
        return [v + o for v, o in zip(value, self.offset, strict=True)]


def plain_value(value: object) -> object:
    """A parameter value as YAML and JSON hold it (a link becomes its mapping)."""
    return value.to_plain() if isinstance(value, Link) else value


@dataclass(frozen=True)
class Step:
    """One process command of a task, with its role bindings and parameter values."""

    index: int
    """1-based position in the expanded task."""
    command: str
    bind: dict[str, str] = field(default_factory=dict)
    params: dict[str, object] = field(default_factory=dict)
    line: int | None = None
    param_lines: dict[str, int] = field(default_factory=dict, compare=False)
    """Line of each parameter value in the task file."""
    name: str | None = None
    """The step's name (``name:``), by which later steps take its outputs."""

    def at(self, index: int) -> Step:
        """This step at position ``index`` of a task: itself when it is there already, else a copy (the same
        values, bindings and lines; a plain copy costs a fraction of ``dataclasses.replace``, which the
        repairs of a 10,000-step task would pay for every step after their first insertion)."""
        if index == self.index:
            return self
        return Step(index, self.command, self.bind, self.params, self.line, self.param_lines, self.name)

    def links(self) -> dict[str, Link]:
        """The parameters whose values come from earlier steps' outputs."""
        return {n: v for n, v in self.params.items() if isinstance(v, Link)}

    def values(self) -> dict[str, object]:
        """The parameters given as values (links left out)."""
        return {n: v for n, v in self.params.items() if not isinstance(v, Link)}


@dataclass(frozen=True)
class Task:
    """A task description: an ordered list of process commands, some of them in loops and branches
    (:mod:`plugnproduce.description.flow`)."""

    MAX_STEPS = 10_000
    """Most steps a task may have once its repeats are expanded."""

    name: str
    steps: tuple[Step, ...]
    file: str
    description: str = ""
    repeat: int = 1
    loops: tuple[Loop, ...] = ()
    branches: tuple[Branch, ...] = ()

    @classmethod
    def repeated(cls, name: str, one_round: Sequence[Step], file: str, description: str = "",
                 repeat: int = 1) -> Task:
        """The task whose steps are ``one_round`` done ``repeat`` times, numbered from 1 in that order.

        The one place a task's repeats are expanded (task files and the HTTP API's tasks alike).
        """
        n = len(one_round)
        steps = tuple(dataclasses.replace(s, index=r * n + i + 1) for r in range(repeat)
                      for i, s in enumerate(one_round))
        return cls(name, steps, file, description, repeat)

    def one_round(self) -> tuple[Step, ...]:
        """The steps as written once, before the repeats."""
        return self.steps[: len(self.steps) // max(self.repeat, 1)]

    def loop_at(self, index: int) -> Loop | None:
        """The outermost loop whose body (either copy) holds step position ``index``, if any."""
        return next(iter(self.loops_at(index)), None)

    def loops_at(self, index: int) -> tuple[Loop, ...]:
        """The loops whose bodies (either copy) hold step position ``index``, outermost first."""
        return enclosing(self.loops, index)

    def loop_starting(self, index: int, end: int) -> Loop | None:
        """The outermost loop that starts at step position ``index`` and ends by position ``end``, if any."""
        return next((lp for lp in outermost_first(self.loops) if lp.entry == index and lp.last <= end), None)

    def branches_of(self, index: int) -> tuple[Branch, ...]:
        """The branches on the outcome of the step at position ``index``, in the order written."""
        return tuple(b for b in self.branches if b.step == index)

    def path(self, index: int) -> str | None:
        """The path step position ``index`` lies on (``loop iteration 1, branch NoPartFound at step 2``)."""
        return path_name(self.loops, self.branches, index)

    def where(self, step: Step, parameter: str | None = None) -> Where:
        """The place of a step (or of one of its parameter values) in the task file."""
        return Where(self.file, step.param_lines.get(parameter, step.line) if parameter else step.line)
