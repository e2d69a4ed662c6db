"""Goal files (YAML) → :class:`Goal`: what must happen, for the planner to turn into a task.

A goal names the process commands that must run (in order, with the values it fixes), an
outcome to repeat until (the plan becomes a loop) and the state concepts devices must be
left in. Every error names the file and line, as the task reader's do.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from plugnproduce.description.model import Link, ProcessDescription
from plugnproduce.description.taskfile import _link, _mapping, _outcome, _plain, _str_map, _unknown_keys
from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.ontology.iris import concept_iri, concept_value
from plugnproduce.ontology.names import did_you_mean
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.safeio import parse_yaml_bytes, read_bytes

MAX_ITEMS = 50
"""Most commands a goal may ask for."""


@dataclass(frozen=True)
class GoalItem:
    """A process command the goal needs run, with the parameter values and role bindings it fixes."""

    command: str
    params: dict[str, object] = field(default_factory=dict)
    bind: dict[str, str] = field(default_factory=dict)
    line: int | None = None


@dataclass(frozen=True)
class Goal:
    """What must happen: commands in order, an outcome to repeat until, device end states."""

    name: str
    achieve: tuple[GoalItem, ...]
    file: str
    description: str = ""
    until: str | None = None
    """The outcome (IRI) the plan loops until; None for a straight plan."""
    max: int = 100
    """Most iterations of the loop."""
    end: dict[str, str] = field(default_factory=dict)
    """Device id → the state concept (IRI) it must be left in."""
    lines: dict[str, int] = field(default_factory=dict, compare=False)
    """Line of each top-level key in the goal file."""


def load_goal(path: str | Path) -> Goal:
    """Read a goal file (YAML)."""
    return parse_goal(read_bytes(path), path)


def parse_goal(data: bytes, source: str | Path) -> Goal:
    """Read a goal from YAML text; ``source`` names it in messages and in ``Goal.file``."""
    p = Path(source)
    top = _mapping(parse_yaml_bytes(data, p), p, "goal")
    _unknown_keys(top, {"goal", "description", "achieve", "until", "max", "end"}, p, "goal")
    if "goal" not in top or "achieve" not in top:
        raise DescriptionError("a goal needs 'goal' (its name) and 'achieve' (the commands that must run)", p, 1)
    items = top["achieve"]
    if not isinstance(items, yaml.SequenceNode) or not items.value or len(items.value) > MAX_ITEMS:
        raise DescriptionError(f"achieve must be a list of 1 to {MAX_ITEMS} commands", p, items.start_mark.line + 1)
    most = _plain(top["max"]) if "max" in top else 100
    if not isinstance(most, int) or isinstance(most, bool) or not 1 <= most <= 1_000_000:
        raise DescriptionError(f"max must be a whole number from 1 to 1000000; found {excerpt(repr(most))}", p,
                               top["max"].start_mark.line + 1)
    end = {}
    for device, concept in _str_map(top.get("end"), p, "end").items():
        if not isinstance(concept, str) or not concept:
            raise DescriptionError(f"end: {excerpt(device)} must name a state concept such as Open", p,
                                   top["end"].start_mark.line + 1)
        end[device] = concept_iri(concept)
    return Goal(name=str(_plain(top["goal"])), achieve=tuple(_item(n, p) for n in items.value), file=str(p),
                description=str(_plain(top["description"]) or "") if "description" in top else "",
                until=_outcome(top, "until", p), max=most, end=end,
                lines={k: v.start_mark.line + 1 for k, v in top.items()})


def _item(node: yaml.Node, p: Path) -> GoalItem:
    line = node.start_mark.line + 1
    m = _mapping(node, p, "achieve")
    _unknown_keys(m, {"command", "params", "bind"}, p, "achieve")
    command = _plain(m["command"]) if "command" in m else None
    if not isinstance(command, str):
        raise DescriptionError("each item of achieve needs 'command': a process command's name", p, line)
    params = {n: _link(v, p, line) for n, v in _str_map(m.get("params"), p, "params").items()}
    if any(isinstance(v, Link) for v in params.values()):
        raise DescriptionError("a goal fixes values; which step's output a parameter takes is the planner's choice",
                               p, line)
    bind = {k: str(v) for k, v in _str_map(m.get("bind"), p, "bind").items()}
    return GoalItem(command, params, bind, line)


def check_terms(goal: Goal, taxonomy: Taxonomy, processes: Mapping[str, ProcessDescription]) -> None:
    """Refuse, at its line, a command, parameter or role the knowledge does not know, or an unknown concept."""
    path = goal.file
    for item in goal.achieve:
        process = processes.get(item.command)
        if process is None:
            raise DescriptionError(f"unknown process command {item.command!r}"
                                   f"{did_you_mean(item.command, sorted(processes))}", path, item.line)
        names = [p.name for p in process.parameters]
        for n in item.params:
            if n not in names:
                raise DescriptionError(f"{item.command} has no parameter {n!r}{did_you_mean(n, names)}",
                                       path, item.line)
        roles = [r.name for r in process.roles]
        for r in item.bind:
            if r not in roles:
                raise DescriptionError(f"{item.command} has no role {r!r}{did_you_mean(r, roles)}", path, item.line)
    for concept in goal.end.values():
        if concept not in taxonomy.superclasses:
            raise DescriptionError(f"end: unknown state concept {concept_value(concept)!r}", path,
                                   goal.lines.get("end"))
    if goal.until is not None and goal.until not in taxonomy.superclasses:
        raise DescriptionError(f"until: unknown outcome {concept_value(goal.until)!r}", path, goal.lines.get("until"))
