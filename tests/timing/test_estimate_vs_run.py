"""The estimate against a simulated run: the simulator takes the same durations, scaled by ``--speed``.

The run's time is what its journal records from the first step to the end, times the speed factor
(simulated seconds). It also holds the controller's own latency per command (its step, messages on
loopback, a timer's millisecond), which the estimate leaves out: 1 to 4 % of the built-in bin-picking task
at speed 1 (``bench/bench_cycle_time.py``). At speed 0.5 it counts half, a margin for a loaded machine.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[2]
BUILTIN = ROOT / "descriptions"
TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          timeout=300, env={**os.environ})


def estimated(task: Path, cell: Path) -> float:
    result = pnp("check", str(task), "--cell", str(cell), "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    return float(json.loads(result.stdout)["cycle_time"]["total_seconds"])


def simulated(task: Path, cell: Path, speed: float, journal: Path) -> float:
    """Simulated seconds from the run's first step to its end, as its journal records them, times the speed
    factor its start records."""
    result = pnp("run", str(task), "--cell", str(cell), "--sim", "--speed", str(speed), "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    assert records[0]["kind"] == "start" and records[0]["speed"] == speed
    first = next(r["t"] for r in records if r["kind"] == "step")
    end = next(r for r in records if r["kind"] == "end")
    assert end["outcome"] == "succeeded"
    return float((end["t"] - first) * records[0]["speed"])


def test_the_builtin_bin_picking_task_runs_within_ten_percent_of_its_estimate(tmp_path: Path) -> None:
    """Issue 27: 30 commands over XIRP and UPnP; each command's record is fsynced while it goes out."""
    task, cell = BUILTIN / "tasks" / "bin-picking.yaml", BUILTIN / "cells" / "bin-picking.yaml"
    estimate = estimated(task, cell)
    run = simulated(task, cell, 0.5, tmp_path / "run.jsonl")  # half as fast as the charts say
    assert abs(run - estimate) <= 0.10 * estimate, (estimate, run)


def test_a_library_s_motion_model_runs_within_ten_percent_of_its_estimate(tmp_path: Path) -> None:
    """The simulated robot moves for the distance over its declared speed, the gripper for its declared times."""
    task, cell = TIMED / "tasks" / "pick-place-timed.yaml", TIMED / "cells" / "timed-cell.yaml"
    estimate = estimated(task, cell)
    assert estimate > 7.0  # the declared durations count (the charts' delays would make it under 2 s)
    run = simulated(task, cell, 1.0, tmp_path / "run.jsonl")
    assert abs(run - estimate) <= 0.10 * estimate, (estimate, run)


def test_speed_needs_a_simulated_cell() -> None:
    result = pnp("run", str(BUILTIN / "tasks" / "pick-and-place.yaml"), "--cell",
                 str(BUILTIN / "cells" / "bin-picking.yaml"), "--speed", "2")
    assert result.returncode == 2
    assert "--speed works on simulated devices" in result.stdout + result.stderr
