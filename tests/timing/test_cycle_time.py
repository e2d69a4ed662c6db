"""The cycle-time estimate of ``pnp check``: each step along its specific process chart, the task as the sum.

The figures follow from the description files: the built-in cell's chart delays (sensor capture 180 ms,
localization 150 ms, robot move 250 ms, gripper close/open 120 ms), and the timed-cell library's declared
durations (a robot at 0.5 m/s times the requested share of it; a gripper's data-sheet times).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).parents[2]
BUILTIN = ROOT / "descriptions"
CELL = BUILTIN / "cells" / "bin-picking.yaml"
TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
TIMED_CELL = TIMED / "cells" / "timed-cell.yaml"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          timeout=300, env={**os.environ})


def estimate(task: Path, cell: Path) -> dict[str, Any]:
    result = pnp("check", str(task), "--cell", str(cell), "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    cycle: dict[str, Any] = json.loads(result.stdout)["cycle_time"]
    return cycle


def seconds(cycle: dict[str, Any]) -> list[tuple[int, str, float]]:
    return [(s["step"], s["command"], s["seconds"]) for s in cycle["steps"]]


def test_check_json_times_each_step_of_the_bin_picking_task_and_the_total() -> None:
    cycle = estimate(BUILTIN / "tasks" / "bin-picking.yaml", CELL)
    # bin-pick: capture 0.18, localize 0.15, approach 0.25, close 0.12, lift 0.25 (each waits for the one before)
    # place: move 0.25, open 0.12, retract 0.25
    assert seconds(cycle) == [
        (i + 1, c, s) for i, (c, s) in enumerate([("bin-pick", 0.95), ("place", 0.62)] * 3)]
    assert cycle["total_seconds"] == pytest.approx(3 * (0.95 + 0.62))


def test_check_text_says_the_total() -> None:
    result = pnp("check", str(BUILTIN / "tasks" / "bin-picking.yaml"), "--cell", str(CELL))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "estimated cycle time: 4.71 s" in result.stdout.splitlines()[-1]


def test_a_loop_of_known_count_counts_every_iteration() -> None:
    cycle = estimate(BUILTIN / "tasks" / "bin-picking-in-rounds.yaml", CELL)
    (loop,) = cycle["loops"]
    assert loop["count"] == 3
    assert cycle["total_seconds"] == pytest.approx(loop["first_iteration_seconds"]
                                                   + 2 * loop["later_iteration_seconds"], abs=0.002)


def test_a_loop_until_an_outcome_counts_once_and_says_so() -> None:
    cycle = estimate(BUILTIN / "tasks" / "bin-picking-until-empty.yaml", CELL)
    (loop,) = cycle["loops"]
    assert loop["count"] is None
    assert loop["later_iteration_seconds"] == pytest.approx(0.33 + 0.62 + 0.62)  # localize, pick, place
    assert cycle["total_seconds"] == pytest.approx(loop["first_iteration_seconds"])
    assert any("counted once" in n for n in cycle["notes"])
    text = pnp("check", str(BUILTIN / "tasks" / "bin-picking-until-empty.yaml"), "--cell", str(CELL)).stdout
    assert "1.57 s per further iteration of steps 1-6" in text


def test_a_motion_model_takes_the_distance_over_the_speed() -> None:
    """The library's robot: 0.5 m/s at full speed; its first move (from a pose no request named) takes its
    chart's 250 ms; the gripper declares Close 0.4 s and Open 0.3 s instead of its chart's 120 ms."""
    cycle = estimate(TIMED / "tasks" / "pick-place-timed.yaml", TIMED_CELL)
    at_half = 0.5 * 0.50  # m/s at speed 50 %
    pick_and_place = 0.5 / at_half + 0.4 + 0.6 / at_half + 0.3 + 0.4 / at_half  # approach, close, carry, open, up
    back = 0.3 / (0.5 * 0.80)
    assert seconds(cycle) == [(1, "move-to", 0.25), (2, "pick-and-place", pytest.approx(pick_and_place)),
                              (3, "move-to", pytest.approx(back))]


def test_parallel_regions_overlap_and_the_longer_one_counts() -> None:
    """The robot moves while the gripper sets its angle (0.5 s declared): a step takes the longer of the two."""
    cycle = estimate(TIMED / "tasks" / "approach-while-opening.yaml", TIMED_CELL)
    at_80 = 0.5 * 0.80
    assert seconds(cycle) == [(1, "move-to", 0.25),
                              (2, "approach-and-open", pytest.approx(0.5 / at_80)),  # the robot's 1.25 s
                              (3, "approach-and-open", 0.5)]  # the gripper's 0.5 s; the robot's 0.25 s overlaps


def test_an_implausible_task_has_no_estimate() -> None:
    result = pnp("check", str(BUILTIN / "tasks" / "bin-picking-invalid.yaml"), "--cell", str(CELL), "--json")
    assert result.returncode == 1
    assert json.loads(result.stdout)["cycle_time"] is None
