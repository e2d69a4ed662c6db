"""Plan: a task that reaches a goal in a cell, or why none does; the goal as PDDL."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.description.model import DeviceDescription
from plugnproduce.knowledge import Knowledge
from plugnproduce.service.descriptions import CellArg, _devices, cell_and_knowledge

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce.description.goalfile import Goal
    from plugnproduce.planning import Plan, Unreachable
    from plugnproduce.reasoning import CheckResult


def plan(goal_or_path: Goal | str | Path, cell_or_path: CellArg, knowledge: Knowledge | None = None,
         catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
         source: str | None = None, minimize: str = "steps") -> Plan | Unreachable:
    """A task that reaches a goal in a cell, from its devices' states (a cell with reported states plans from
    those), or why none does, with the cheapest catalogue device (built-in and library) that would make one.
    ``source`` names the written task file; ``minimize``: ``steps`` (the shortest plan) or ``cycle-time`` (the
    one of least estimated cycle time)."""
    from plugnproduce.description.goalfile import Goal, load_goal
    from plugnproduce.planning import plan as make_plan

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    goal = goal_or_path if isinstance(goal_or_path, Goal) else load_goal(goal_or_path)
    devices = list(k.devices) if catalogue_or_folder is None else _devices(catalogue_or_folder, k)
    return make_plan(goal, the_cell, k, devices, source=source, minimize=minimize)


def plan_pddl(goal_or_path: Goal | str | Path, cell_or_path: CellArg,
              knowledge: Knowledge | None = None) -> tuple[str, str]:
    """A goal without ``until`` as a PDDL domain and problem whose optimal plans cost what :func:`plan` optimises."""
    from plugnproduce.description.goalfile import Goal, load_goal
    from plugnproduce.planning.pddl import export

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    return export(goal_or_path if isinstance(goal_or_path, Goal) else load_goal(goal_or_path), the_cell, k)


def goal_from_text(data: bytes | str, name: str) -> Goal:
    """Read a goal from YAML text (the HMI's Goal view); ``name`` names it in messages."""
    from plugnproduce.description.goalfile import parse_goal

    return parse_goal(data.encode("utf-8") if isinstance(data, str) else data, name)


def goal_findings(goal: Goal, checked: CheckResult) -> list[str]:
    """The check's problems of a planned task as lines for the goal's author: a problem with a value the goal
    fixes is placed at the goal's item (``goal.yaml:LINE: …``), as the planned task is not a file of theirs."""
    lines = []
    for problem in checked.problems:
        item = next((i for i in goal.achieve if i.command == problem.command and problem.parameter in i.params), None)
        lines.append(f"{goal.file}:{item.line}: {problem.text}" if item is not None else problem.text)
    return lines
