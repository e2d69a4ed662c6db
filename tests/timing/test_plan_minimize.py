"""``pnp plan --minimize steps|cycle-time``: of the plans equally short and measuring as much, the fastest."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).parents[2]
TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
GOAL = TIMED / "goals" / "move-a-part.yaml"
TWO_ROBOTS = TIMED / "cells" / "two-robots.yaml"


def plan(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", "plan", *args], capture_output=True, text=True,
                          timeout=300, env={**os.environ})


def planned(goal: Path, cell: Path, minimize: str) -> dict[str, Any]:
    result = plan(str(goal), "--cell", str(cell), "--minimize", minimize, "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    out: dict[str, Any] = json.loads(result.stdout)
    return out


def test_cycle_time_takes_the_fast_robot(tmp_path: Path) -> None:
    """Both robots can do it in one step; the slow one moves at 0.25 m/s (speed 50 % of 0.5 m/s), the fast one
    takes 250 ms a move: pick 0.25 + close 0.4 + carry 0.25 + open 0.3 + retract 0.25 = 1.45 s."""
    fastest = planned(GOAL, TWO_ROBOTS, "cycle-time")
    assert fastest["steps"] == 1
    assert "robot: tc-fast-robot" in fastest["task"]
    assert fastest["cycle_time"]["total_seconds"] == 1.45
    assert fastest["check"]["plausible"]
    shortest = planned(GOAL, TWO_ROBOTS, "steps")
    assert shortest["steps"] == 1
    assert fastest["cycle_time"]["total_seconds"] <= shortest["cycle_time"]["total_seconds"]


def test_the_text_says_the_estimate_and_the_file_checks(tmp_path: Path) -> None:
    task = tmp_path / "planned.yaml"
    result = plan(str(GOAL), "--cell", str(TWO_ROBOTS), "--minimize", "cycle-time", "-o", str(task))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "estimated cycle time: 1.45 s" in result.stdout
    check = subprocess.run([sys.executable, "-m", "plugnproduce", "check", str(task), "--cell", str(TWO_ROBOTS)],
                           capture_output=True, text=True, timeout=300, env={**os.environ})
    assert check.returncode == 0, check.stdout + check.stderr
    assert "estimated cycle time: 1.45 s" in check.stdout


def test_the_bin_emptying_goal_gets_a_longer_but_faster_loop(tmp_path: Path) -> None:
    """pick = approach, close, lift (0.62 s); move-to then close-gripper skip the lift (0.37 s): one step more
    per iteration, 0.25 s less. The faster plan still empties a simulated bin."""
    goal, cell = ROOT / "descriptions" / "goals" / "empty-the-bin.yaml", ROOT / "descriptions" / "cells" / "bin-picking.yaml"
    steps, fastest = planned(goal, cell, "steps"), planned(goal, cell, "cycle-time")
    per_iteration = [p["cycle_time"]["loops"][0]["later_iteration_seconds"] for p in (steps, fastest)]
    assert (steps["steps"], fastest["steps"]) == (3, 4)
    assert per_iteration == [1.57, 1.32]
    task = tmp_path / "fast.yaml"
    task.write_text(fastest["task"])
    run = subprocess.run([sys.executable, "-m", "plugnproduce", "run", str(task), "--sim", "--bin-parts", "2",
                          "--journal", str(tmp_path / "run.jsonl"), "--json"],
                         capture_output=True, text=True, timeout=300, env={**os.environ})
    assert run.returncode == 0, run.stdout + run.stderr
    records = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    assert [r["produced"] for r in records if r["kind"] == "value" and r.get("value") == "outcome"][-1] == "BinEmpty"


def test_an_unknown_criterion_is_bad_input() -> None:
    result = plan(str(GOAL), "--cell", str(TWO_ROBOTS), "--minimize", "energy")
    assert result.returncode == 2
    assert "expected steps or cycle-time" in result.stdout + result.stderr
