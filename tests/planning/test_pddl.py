"""The goal as PDDL: Fast Downward (through unified-planning, optimal) finds no cheaper plan than ``pnp plan``."""

from __future__ import annotations

import random
import re
import subprocess
import sys
from pathlib import Path

import pytest
from unified_planning.engines import PlanGenerationResultStatus
from unified_planning.io import PDDLReader
from unified_planning.shortcuts import OneshotPlanner, get_environment

from plugnproduce import service
from plugnproduce.description.goalfile import Goal, GoalItem, parse_goal
from plugnproduce.errors import DescriptionError
from plugnproduce.planning import Plan
from plugnproduce.planning.pddl import PENALTY, STEP

CELL = service.builtin("cells", "bin-picking.yaml")
MACHINE_TENDING = Path(__file__).parents[1] / "data" / "libraries" / "machine-tending" / "cells" / "machine-tending.yaml"
get_environment().credits_stream = None


def our_cost(found: Plan) -> int:
    """What the planner optimises, as the PDDL action costs state it."""
    roles = sum(len(s.bind) for s in found.task.steps)
    return PENALTY * (len(found.blind) + len(found.wasted)) + STEP * found.steps + roles


def fast_downward(goal: Goal, cell: Path, tmp_path: Path) -> tuple[PlanGenerationResultStatus, int | None]:
    """Fast Downward's optimal plan of the exported PDDL: its status and cost."""
    k = service.knowledge_for_cell(cell, service.knowledge())
    domain, problem = service.plan_pddl(goal, cell, k)
    (tmp_path / "domain.pddl").write_text(domain)
    (tmp_path / "problem.pddl").write_text(problem)
    read = PDDLReader().parse_problem(str(tmp_path / "domain.pddl"), str(tmp_path / "problem.pddl"))
    with OneshotPlanner(name="fast-downward-opt") as planner:
        result = planner.solve(read)
    if result.plan is None:
        return result.status, None
    costs = dict(zip(re.findall(r"\(:action (\S+)", domain),  # each action's cost, as the domain states it
                     map(int, re.findall(r"\(increase \(total-cost\) (\d+)\)", domain)), strict=True))
    return result.status, sum(costs.get(a.action.name, 0) for a in result.plan.actions)  # (compiled goals: 0)


GOALS = {
    "drop": "goal: drop\nachieve:\n  - command: place\n",
    "park": "goal: park\nachieve:\n  - command: place\n  - command: move-to\nend: {gripper: Closed}\n",
    "pick-at-the-found-pose": "goal: p\nachieve:\n  - command: pick\n  - command: place\n"
                              "    params: {place_pose: [0.6, -0.2, 0.1, 0, 180, 0]}\nend: {gripper: Open}\n",
}


@pytest.mark.parametrize("name", sorted(GOALS))
def test_fast_downward_finds_no_cheaper_plan_on_the_bin_picking_cell(tmp_path: Path, name: str) -> None:
    goal = parse_goal(GOALS[name].encode(), f"{name}.yaml")
    ours = service.plan(goal, CELL)
    assert isinstance(ours, Plan)
    status, cost = fast_downward(goal, CELL, tmp_path)
    assert status == PlanGenerationResultStatus.SOLVED_OPTIMALLY
    assert our_cost(ours) == cost


def test_fast_downward_finds_no_cheaper_plan_in_a_library_cell(tmp_path: Path) -> None:
    goal = parse_goal(b"goal: one\nachieve:\n  - command: machine\n    params: {nc_program: O2001}\n"
                      b"  - command: unload-machine\nend: {mt-cnc: DoorClosed}\n", "one.yaml")
    ours = service.plan(goal, MACHINE_TENDING)
    assert isinstance(ours, Plan) and ours.steps == 7
    status, cost = fast_downward(goal, MACHINE_TENDING, tmp_path)
    assert status == PlanGenerationResultStatus.SOLVED_OPTIMALLY and our_cost(ours) == cost


@pytest.mark.parametrize("seed", range(4))
def test_fast_downward_agrees_on_generated_goals(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    offered = [o.command for o in service.capabilities(CELL).offered]
    goal = Goal(f"generated-{seed}", tuple(GoalItem(rng.choice(offered)) for _ in range(rng.randint(1, 3))),
                f"generated-{seed}.yaml")
    ours = service.plan(goal, CELL)
    status, cost = fast_downward(goal, CELL, tmp_path)
    if isinstance(ours, Plan):
        assert status == PlanGenerationResultStatus.SOLVED_OPTIMALLY and our_cost(ours) == cost, goal
    else:
        assert cost is None or cost >= STEP * 13, goal  # we search 12 steps at most


def test_a_looping_goal_has_no_pddl_form_and_says_so(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match="PDDL cannot state"):
        service.plan_pddl(service.builtin("goals", "empty-the-bin.yaml"), CELL)
    done = subprocess.run([sys.executable, "-m", "plugnproduce", "plan", str(service.builtin("goals", "empty-the-bin.yaml")),
                           "--cell", str(CELL), "--pddl", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and ":7: a goal with 'until' plans a loop" in done.stderr
