"""``pnp repair --rank time``: the repairs of a task ordered by the cycle time they add, each with its estimate."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).parents[2]
TASK = ROOT / "descriptions" / "tasks" / "bin-picking-invalid.yaml"
CELL = ROOT / "descriptions" / "cells" / "bin-picking.yaml"


def repair(*options: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", "repair", str(TASK), "--cell", str(CELL),
                           "--top", "5", *options], capture_output=True, text=True, timeout=300, env={**os.environ})


def repairs(*options: str) -> list[dict[str, Any]]:
    result = repair(*options, "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    found: list[dict[str, Any]] = json.loads(result.stdout)["repairs"]
    return found


def edits(r: dict[str, Any]) -> str:
    return "; ".join(e["text"] for e in r["edits"])


def test_rank_time_puts_the_repair_that_adds_least_time_first() -> None:
    """Two bin-picks and a place: removing a bin-pick leaves 0.95 + 0.62 s; opening the gripper in between adds
    its 0.12 s; a place in between adds 0.62 s; the swap runs what the task had, in another order."""
    by_time = repairs("--rank", "time")
    assert [(edits(r), r["cycle_time"], r["rank"]) for r in by_time] == [
        ("remove step 1 (bin-pick)", 1.57, 1),
        ("swap step 2 (bin-pick) with step 3 (place)", 2.52, 2),
        ("insert open-gripper before step 2 (bin-pick)", 2.64, 3),
        ("insert place before step 2 (bin-pick)", 3.14, 4),
    ]


def test_the_default_ranking_stays_by_side_effects_and_gives_the_estimates_too() -> None:
    default = repairs()
    by_time = {edits(r): r["cycle_time"] for r in repairs("--rank", "time")}
    assert edits(default[0]) == "insert place before step 2 (bin-pick)"  # no side effect that matters
    assert {edits(r): r["cycle_time"] for r in default} == by_time


def test_the_text_shows_each_estimate() -> None:
    result = repair("--rank", "time")
    assert result.returncode == 0, result.stdout + result.stderr
    first = result.stdout.split("repair 1 (cost 4):\n")[1].split("resulting task:")[0]
    assert "  - remove step 1 (bin-pick) [cost 4]\n  estimated cycle time: 1.57 s\n" in first


def test_an_unknown_ranking_is_bad_input() -> None:
    result = repair("--rank", "cost")
    assert result.returncode == 2
    assert "expected side-effects or time" in result.stdout + result.stderr
