"""Benchmark of ``pnp plan``'s planner against Fast Downward on the same goals (prints figures; not a test).

    python bench/bench_planner.py [--sizes 5x4,10x4,20x4,40x4,5x12,5x24,5x40]

Each size NxD is a goal of N commands (pick, place, pick, place, ...: N steps at the least) on a cell of D
devices: the bin-picking cell's robot, gripper, 3D sensor and PC, copied D/4 times under new ids (so each
role has D/4 devices to choose from). Our planner (clingo, growing horizon, the knowledge loaded once:
warm) and Fast Downward (optimal, `fast-downward-opt` through unified-planning, on the PDDL that
`pnp plan --pddl` writes for the goal) plan each goal; both must give plans of the same cost. Times are
CPU seconds (user+sys, ours in-process, Fast Downward's translator and search as child processes plus
reading the PDDL in this process), with wall seconds and the machine's load beside them.
Target: our planner faster than Fast Downward on these domains, and growing no faster.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import re
import resource
import sys
import tempfile
import time
from pathlib import Path

from unified_planning.io import PDDLReader
from unified_planning.shortcuts import OneshotPlanner, get_environment

from plugnproduce import planning, service
from plugnproduce.description.goalfile import Goal, GoalItem
from plugnproduce.description.model import Cell
from plugnproduce.planning.pddl import PENALTY, STEP, export

K = service.knowledge()
get_environment().credits_stream = None


def cpu(children: bool = False) -> float:
    """CPU seconds (user+sys) of this process, or of its finished children."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN if children else resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def cell_of(devices: int) -> Cell:
    """The bin-picking cell's four devices, ``devices // 4`` times each under new ids."""
    base = service.cell(service.builtin("cells", "bin-picking.yaml"), K)
    copies = [dataclasses.replace(d, id=f"{d.id}-{i}") for i in range(devices // 4) for d in base.devices]
    return Cell(f"bin-picking-x{devices // 4}", tuple(copies))


def goal_of(steps: int) -> Goal:
    return Goal(f"pick-place-{steps}", tuple(GoalItem("pick" if i % 2 == 0 else "place") for i in range(steps)),
                f"pick-place-{steps}.yaml")


def ours(goal: Goal, cell: Cell, max_steps: int) -> tuple[float, float, int]:
    wall, start = time.perf_counter(), cpu()
    found = planning.plan(goal, cell, K, max_steps=max_steps)
    assert isinstance(found, planning.Plan), found
    roles = sum(len(s.bind) for s in found.task.steps)
    cost = PENALTY * (len(found.blind) + len(found.wasted)) + STEP * found.steps + roles
    return cpu() - start, time.perf_counter() - wall, cost


def fast_downward(goal: Goal, cell: Cell) -> tuple[float, float, int]:
    domain, problem = export(goal, cell, K)
    folder = Path(tempfile.mkdtemp())
    (folder / "domain.pddl").write_text(domain)
    (folder / "problem.pddl").write_text(problem)
    wall, start, start_children = time.perf_counter(), cpu(), cpu(children=True)
    read = PDDLReader().parse_problem(str(folder / "domain.pddl"), str(folder / "problem.pddl"))
    with OneshotPlanner(name="fast-downward-opt") as planner:
        result = planner.solve(read)
    spent = cpu() - start + cpu(children=True) - start_children
    assert result.plan is not None, result.status
    costs = dict(zip(re.findall(r"\(:action (\S+)", domain),
                     map(int, re.findall(r"\(increase \(total-cost\) (\d+)\)", domain)), strict=True))
    return spent, time.perf_counter() - wall, sum(costs.get(a.action.name, 0) for a in result.plan.actions)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="5x4,10x4,20x4,40x4,5x12,5x24,5x40",
                        help="STEPSxDEVICES, comma-separated")
    args = parser.parse_args()
    print(f"load {os.getloadavg()[0]:.1f}; CPU seconds (wall in brackets); same plan cost required")
    print(f"{'steps x devices':>16} {'ours':>16} {'Fast Downward':>18} {'FD / ours (CPU)':>16}")
    for size in args.sizes.split(","):
        steps, devices = map(int, size.split("x"))
        goal, cell = goal_of(steps), cell_of(devices)
        a_cpu, a_wall, a_cost = ours(goal, cell, steps + 2)
        b_cpu, b_wall, b_cost = fast_downward(goal, cell)
        assert a_cost == b_cost, (size, a_cost, b_cost)
        print(f"{size:>16} {a_cpu:8.2f} ({a_wall:5.2f}) {b_cpu:10.2f} ({b_wall:5.2f}) {b_cpu / a_cpu:15.1f}x",
              flush=True)
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    sys.exit(main())
