"""The plan of a generated chart, read from its model: which state runs at each step, in order.

A generated task chart (and the controller of a closed-world chart) keeps every distinct step
chart once and runs them by ``pnp_plan`` in its datamodel; the state ``next_step`` picks the
body of the next step (``pnp_plan[pnp_step] == N``). A device program does the same with
segments of its own states. Pictures draw the steps in order from this, not the states as written.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass

from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.statechart.model import Chart, Parallel, State, StateNode

PLAN, PICKER = "pnp_plan", "next_step"
_PICK = re.compile(r"^\s*pnp_plan\[pnp_step\]\s*==\s*(\d+)\s*$")


def pnp(node: StateNode | Chart, attribute: str) -> str | None:
    """The value of a ``pnp:`` annotation of a state, or None."""
    return node.extra_attrs.get("{" + PNP_IRI + "}" + attribute)


@dataclass(frozen=True)
class PlanStep:
    """One step of the task as the plan runs it."""

    number: int
    """Its place in the task, from 1."""
    body: str
    """The id of the state that runs it (shared by the steps that run the same chart)."""
    command: str | None
    """The process it runs (None for a device program's segment)."""
    chart: str | None
    """The file of its Specific Process State Chart, when the chart names it."""
    binding: tuple[tuple[str, str], ...]
    """(role, device) for each role of the process."""

    @property
    def title(self) -> str:
        """``3 · bin-pick``."""
        return f"{self.number} · {self.command or self.body}"

    def binding_text(self, per_line: int = 2) -> list[str]:
        """The binding as short lines, ``role: device``, a few to a line."""
        pairs = [f"{role}: {device}" for role, device in self.binding]
        return [", ".join(pairs[i:i + per_line]) for i in range(0, len(pairs), per_line)]


@dataclass(frozen=True)
class Plan:
    """The steps of a chart run by a plan, and where the plan lives in the chart."""

    container: Chart | State
    """The state (or the chart) whose child is ``next_step``."""
    picker: State
    """``next_step``."""
    end: str | None
    """The state entered after the last step."""
    steps: tuple[PlanStep, ...]

    @property
    def bodies(self) -> dict[str, StateNode]:
        """Each distinct step body, by id, in the order of the container's children."""
        ids = {s.body for s in self.steps}
        return {c.id: c for c in self.container.children if c.id in ids}

    @property
    def is_task(self) -> bool:
        """True when the steps run processes (a task or closed-world chart), not device segments."""
        return any(isinstance(b, Parallel) for b in self.bodies.values())


def _numbers(chart: Chart) -> list[int] | None:
    text = next((d.text or d.expr for d in chart.data if d.id == PLAN), None)  # inline content, or an expression
    if text is None:
        return None
    try:
        value = ast.literal_eval(text.strip())
    except (ValueError, SyntaxError):
        return None
    if not isinstance(value, list) or not all(isinstance(v, int) for v in value):
        return None
    return value[:value.index(0)] if 0 in value else value


def _picker(container: Chart | State | Parallel) -> tuple[Chart | State, State] | None:
    for child in container.children:
        if isinstance(child, State) and child.id == PICKER and isinstance(container, Chart | State):
            return container, child
    for child in container.children:
        if isinstance(child, State | Parallel):
            found = _picker(child)
            if found:
                return found
    return None


def _step(number: int, body: StateNode) -> PlanStep:
    binding: list[tuple[str, str]] = []
    if isinstance(body, Parallel):
        for region in body.children:
            role, device = pnp(region, "role"), pnp(region, "device")
            if role and device:
                binding.append((role, device))
    return PlanStep(number, body.id or "", pnp(body, "command"), pnp(body, "chart"), tuple(binding))


def find_plan(chart: Chart) -> Plan | None:
    """The plan of a generated task, closed-world or device-program chart; None for other charts."""
    numbers = _numbers(chart)
    found = _picker(chart) if numbers is not None else None
    if numbers is None or found is None:
        return None
    container, picker = found
    targets: dict[int, str] = {}
    for t in picker.transitions:
        match = _PICK.match(t.cond or "")
        if match and t.targets:
            targets[int(match.group(1))] = t.targets[0]
    children = {c.id: c for c in container.children if c.id}
    if any(n not in targets or targets[n] not in children for n in numbers):
        return None
    steps = tuple(_step(i, children[targets[n]]) for i, n in enumerate(numbers, start=1))
    return Plan(container, picker, targets.get(0), steps)
