"""``pnp batch --cycle-time`` and ``--pareto`` on a catalogue of the built-in devices and a library's timed ones."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
TASK = TIMED / "tasks" / "pick-place-timed.yaml"
CONFIGS = [
    {"config": "fast", "devices": ["robot", "gripper"]},              # 32000 + 1800: chart delays
    {"config": "timed", "devices": ["tc-robot", "tc-gripper"]},       # 30000 + 2000: declared, slow
    {"config": "timed-robot", "devices": ["tc-robot", "gripper"]},    # 30000 + 1800: the cheapest
    {"config": "timed-gripper", "devices": ["robot", "tc-gripper"]},  # 32000 + 2000: dearer and slower than fast
    {"config": "no-gripper", "devices": ["robot"]},
]


def batch(tmp_path: Path, *options: str) -> list[dict[str, Any]]:
    configs = tmp_path / "configs.jsonl"
    configs.write_text("".join(json.dumps(c) + "\n" for c in CONFIGS))
    result = subprocess.run([sys.executable, "-m", "plugnproduce", "--library", str(TIMED), "batch", str(configs),
                             "--task", str(TASK), *options], capture_output=True, text=True, timeout=300,
                            env={**os.environ})
    assert result.returncode == 0, result.stdout + result.stderr
    return [json.loads(line) for line in result.stdout.splitlines()]


def test_every_configuration_gets_its_cost_and_cycle_time(tmp_path: Path) -> None:
    rows = {r["config"]: r for r in batch(tmp_path, "--cycle-time")}
    assert [r["config"] for r in batch(tmp_path, "--cycle-time")] == [c["config"] for c in CONFIGS]
    assert {k: r["cost"] for k, r in rows.items()} == {"fast": 33800, "timed": 32000, "timed-robot": 31800,
                                                       "timed-gripper": 34000, "no-gripper": 32000}
    times = {k: r["cycle_time"]["pick-place-timed"] for k, r in rows.items()}
    assert times["no-gripper"] is None  # not plausible there: no estimate
    assert times["timed"] == 7.7  # as pnp check estimates it in the library's own cell
    # the timed robot's moves (distance over speed) are slower than the chart's 250 ms; so is the timed gripper
    assert times["fast"] < times["timed-gripper"] < times["timed-robot"] < times["timed"]
    assert rows["fast"]["plausible"] == ["pick-place-timed"]  # the report's own fields stay


def test_pareto_prints_the_front_of_cost_and_cycle_time(tmp_path: Path) -> None:
    front = batch(tmp_path, "--pareto")
    assert [(p["config"], p["cost"]) for p in front] == [("timed-robot", 31800), ("fast", 33800)]
    assert front[0]["cycle_time"] > front[1]["cycle_time"]


def test_cycle_time_refuses_csv(tmp_path: Path) -> None:
    configs = tmp_path / "configs.jsonl"
    configs.write_text(json.dumps(CONFIGS[0]) + "\n")
    result = subprocess.run([sys.executable, "-m", "plugnproduce", "--library", str(TIMED), "batch", str(configs),
                             "--task", str(TASK), "--pareto", "-o", str(tmp_path / "out.csv")],
                            capture_output=True, text=True, timeout=300, env={**os.environ})
    assert result.returncode == 2
    assert "no .csv output" in result.stdout + result.stderr
