"""A device that takes its poses in another pose unit than the process gives them (tests/data/libraries/mm-arm:
an arm whose TargetPose is in "mm deg", the move-to process's target_pose in "m deg"): each pose is converted
per component before it leaves the controller, and its reach is judged in the device's unit."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "mm-arm"
CELL = LIBRARY / "cells" / "mm-arm.yaml"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=180)


def test_a_literal_and_a_default_pose_go_out_in_millimetres(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(LIBRARY / "tasks" / "move-near.yaml"), "--cell", str(CELL), "--sim",
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    poses = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r.get("device") == "mm-arm"]
    assert poses == [[600.0, 0.0, 0.0, 0.0, 180.0, 0.0], [300.0, 0.0, 400.0, 0.0, 180.0, 0.0]]


def test_the_generated_chart_sends_millimetres(tmp_path: Path) -> None:
    out = tmp_path / "gen"
    result = pnp("generate", str(LIBRARY / "tasks" / "move-near.yaml"), "--cell", str(CELL), "-o", str(out))
    assert result.returncode == 0, result.stderr
    text = "".join(p.read_text() for p in sorted(out.glob("*.scxml")))
    assert 'expr="[600, 0, 0, 0, 180, 0]"' in text
    assert "[0.6, 0, 0" not in text


def test_a_pose_within_the_reach_in_millimetres_is_plausible() -> None:
    result = pnp("check", str(LIBRARY / "tasks" / "move-near.yaml"), "--cell", str(CELL))
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_pose_two_metres_away_is_beyond_a_reach_of_1450_mm() -> None:
    task = LIBRARY / "tasks" / "move-far.yaml"
    result = pnp("check", str(task), "--cell", str(CELL))
    assert result.returncode == 1, result.stdout + result.stderr
    assert "1450 mm" in result.stdout and "2000 mm" in result.stdout
    assert f"{task.name}:5" in result.stdout
