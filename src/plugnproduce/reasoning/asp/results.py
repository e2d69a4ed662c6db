"""What the reasoner answers: plain dataclasses. Infeasible and implausible are results, not exceptions."""

from __future__ import annotations

import re
from dataclasses import field

from plugnproduce.deferred import dataclass
from plugnproduce.description.model import Task, Where, plain_value

_CURIE = re.compile(r" \((?:[A-Za-z][\w-]*:[\w-]+|https?://[^)\s]+)\)")
"""The ``(prefix:Term)`` a reason's text adds after each label for the engineer."""


@dataclass(frozen=True)
class Reason:
    """One reason, as a sentence an operator understands, with the terms and places it rests on."""

    code: str
    """Kind of reason: ``no_skill``, ``lacks_state``, ``unreachable``, ``wrong_state``, ``no_device``, ...."""
    text: str
    iris: tuple[str, ...] = ()
    """Ontology terms (and process, role, device IRIs) the reason names."""
    where: tuple[Where, ...] = ()
    """Description files and lines the reason rests on, most specific first."""

    def __str__(self) -> str:
        return f"{self.where[0]}: {self.text}" if self.where else self.text

    @property
    def plain(self) -> str:
        """The sentence in plain words: the labels without the ontology terms they stand for."""
        return _CURIE.sub("", self.text)

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"code": self.code, "text": self.text, "plain": self.plain, "iris": list(self.iris),
                "where": [str(w) for w in self.where]}


@dataclass(frozen=True)
class Offer:
    """An offered process command: valid role bindings (role → device), how many there are, who can play each role."""

    command: str
    label: str
    bindings: tuple[dict[str, str], ...]
    """One binding (a witness), or every one when asked for all."""
    binding_count: int = 0
    """How many valid role bindings there are (without listing them)."""
    role_devices: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """Per role (in role order), the devices of the cell that can fill it."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"command": self.command, "label": self.label, "bindings": [dict(b) for b in self.bindings],
                "binding_count": self.binding_count,
                "role_devices": {r: list(ds) for r, ds in self.role_devices.items()}}


@dataclass(frozen=True)
class NotOffered:
    """A process command the cell cannot run, and why."""

    command: str
    label: str
    reasons: tuple[Reason, ...]

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"command": self.command, "label": self.label, "reasons": [r.to_json() for r in self.reasons]}


@dataclass(frozen=True)
class Capabilities:
    """What a cell can do: offered process commands with their bindings; the others with reasons."""

    cell: str
    offered: tuple[Offer, ...]
    not_offered: tuple[NotOffered, ...]

    def offers(self, command: str) -> bool:
        """Whether ``command`` is offered."""
        return any(o.command == command for o in self.offered)

    def commands(self) -> list[str]:
        """The offered command names, sorted."""
        return sorted(o.command for o in self.offered)

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"cell": self.cell, "offered": [o.to_json() for o in self.offered],
                "not_offered": [n.to_json() for n in self.not_offered]}


@dataclass(frozen=True)
class Problem:
    """Why one step of a task is not plausible."""

    step: int
    command: str
    kind: str
    """``wrong_state``, ``stuck``, ``no_device``, ``ambiguous``, ``absent``, ``cannot_play``, ``unknown_role``,
    ``unknown_command``, ``bad_type``, ``too_low``, ``too_high``, ``unknown_param``, ``bad_link``."""
    reason: Reason
    where: Where
    """The step (or parameter value) in the task file."""
    role: str | None = None
    device: str | None = None
    state: str | None = None
    """The chart state the device is in when the step starts."""
    state_concept: str | None = None
    needed: str | None = None
    """The state concept the step needs the device in."""
    parameter: str | None = None

    @property
    def text(self) -> str:
        """The problem as a sentence."""
        return self.reason.text

    def __str__(self) -> str:
        return f"{self.where}: {self.reason.text}"

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"step": self.step, "command": self.command, "kind": self.kind, "text": self.reason.text,
                "plain": self.reason.plain, "where": str(self.where), "role": self.role, "device": self.device,
                "state": self.state,
                "state_concept": self.state_concept, "needed": self.needed, "parameter": self.parameter,
                "iris": list(self.reason.iris), "rests_on": [str(w) for w in self.reason.where]}


@dataclass(frozen=True)
class StepCheck:
    """One step as the check saw it: its bindings and the chart state of every device before it."""

    index: int
    command: str
    bindings: dict[str, str]
    states: dict[str, str]
    """Device → chart state when the step starts."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"step": self.index, "command": self.command, "bindings": dict(self.bindings),
                "states": dict(self.states)}


@dataclass(frozen=True)
class LinkSafety:
    """One parameter taken from an earlier step's output, and whether the check proves it safe."""

    step: int
    command: str
    parameter: str
    source: str
    """``STEP.OUTPUT``."""
    device: str
    proven: bool
    why: str

    def __str__(self) -> str:
        verdict = "proven within the contract" if self.proven else "checked at run time"
        return f"step {self.step} ({self.command}): {self.parameter} from {self.source}: {verdict} ({self.why})"

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"step": self.step, "command": self.command, "parameter": self.parameter, "source": self.source,
                "device": self.device, "proven": self.proven, "why": self.why,
                "checked": "before the run" if self.proven else "at run time"}


@dataclass(frozen=True)
class CheckResult:
    """The plausibility of a task in a cell."""

    task: str
    cell: str
    plausible: bool
    problems: tuple[Problem, ...]
    steps: tuple[StepCheck, ...]
    final_states: dict[str, str] = field(default_factory=dict)
    links: tuple[LinkSafety, ...] = ()
    """Per value taken from an earlier step's output: proven within its device's contract, or checked at run
    time (:class:`plugnproduce.reasoning.checks.linksafety.LinkSafety`)."""

    def bindings(self) -> list[dict[str, str]]:
        """Role bindings per step (for code generation; complete only when plausible)."""
        return [dict(s.bindings) for s in self.steps]

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"task": self.task, "cell": self.cell, "plausible": self.plausible,
                "problems": [p.to_json() for p in self.problems], "steps": [s.to_json() for s in self.steps],
                "final_states": dict(self.final_states), "links": [link.to_json() for link in self.links]}


@dataclass(frozen=True)
class StepExplanation:
    """Why step ``step`` is (not) plausible: every device's state before it, and the reasons."""

    step: int
    command: str
    plausible: bool
    states: tuple[Reason, ...]
    """One sentence per device the step uses: its state, where it came from, what the step needs."""
    problems: tuple[Problem, ...]

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"step": self.step, "command": self.command, "plausible": self.plausible,
                "states": [r.to_json() for r in self.states], "problems": [p.to_json() for p in self.problems]}


@dataclass(frozen=True)
class ProcessExplanation:
    """Why a process command is (not) offered in a cell."""

    command: str
    label: str
    offered: bool
    bindings: tuple[dict[str, str], ...]
    reasons: tuple[Reason, ...]

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"command": self.command, "label": self.label, "offered": self.offered,
                "bindings": [dict(b) for b in self.bindings], "reasons": [r.to_json() for r in self.reasons]}


@dataclass(frozen=True)
class RepairCosts:
    """What each edit costs. Defaults: inserting open-gripper (one role) costs 2, the cheapest fix of a
    gripper left closed; a swap (3) or a remove (4) costs more; adding a device costs 5 + price/10,000."""

    insert: float = 1.0
    insert_per_role: float = 1.0
    remove: float = 4.0
    swap: float = 3.0
    rebind: float = 2.0
    """Also the cost of binding a role the task leaves ambiguous, and of dropping an unknown role's binding."""
    reset: float = 1.0
    """Reset a parameter value that does not fit to its default (or drop an undeclared parameter)."""
    add_device: float = 5.0
    add_device_per_price: float = 1.0 / 10000

    def to_json(self) -> dict[str, float]:
        """A JSON-ready dict."""
        return dict(self.__dict__)


@dataclass(frozen=True)
class Edit:
    """One edit of a repair."""

    kind: str
    """``insert``, ``remove``, ``swap``, ``rebind``, ``bind``, ``unbind``, ``reset`` or ``add``."""
    text: str
    cost: float
    step: int | None = None
    """The original step the edit concerns (for insert: the step it is inserted before)."""
    command: str | None = None
    role: str | None = None
    device: str | None = None
    parameter: str | None = None

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {k: v for k, v in self.__dict__.items() if v is not None}


@dataclass(frozen=True)
class Repair:
    """A set of edits that makes the task plausible, its cost, and the resulting task."""

    rank: int
    cost: float
    edits: tuple[Edit, ...]
    task: Task
    added_devices: tuple[str, ...] = ()
    origins: tuple[int, ...] = field(default=(), compare=False, repr=False)
    """For each step of the flat repaired task, the original step position it keeps (0 if inserted); empty once
    the repair is lifted onto the written task (:mod:`plugnproduce.reasoning.repairs.lifting`)."""
    unrolls: str | None = None
    """Why the resulting task writes the original's loops and branches out step by step (None: it keeps them)."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict: the task as its steps (as the task file writes them when it has loops or branches),
        and ``unrolls``: whether it writes the original's loops and branches out step by step (``note``: why)."""
        from plugnproduce.description.taskfile import task_entries  # the task writer: YAML, for a repair's JSON

        steps = task_entries(self.task) if self.task.loops or self.task.branches else [
            {"command": s.command, **({"bind": dict(s.bind)} if s.bind else {}),
             **({"params": {n: plain_value(v) for n, v in s.params.items()}} if s.params else {})}
            for s in self.task.steps]
        return {"rank": self.rank, "cost": self.cost, "edits": [e.to_json() for e in self.edits],
                "added_devices": list(self.added_devices), "task": {"task": self.task.name, "steps": steps},
                "unrolls": self.unrolls is not None, **({"note": self.unrolls} if self.unrolls else {})}
