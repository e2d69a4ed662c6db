"""``pnp run bin-picking-then-home.yaml --sim``: the branch the bin-picking PC's outcome takes is the one that runs."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from plugnproduce import service
from tests.executor.test_run_until_empty import SPEED

TASK = service.builtin("tasks", "bin-picking-then-home.yaml")


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)


def journal_of(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def test_parts_are_picked_while_found_and_the_robot_goes_home_when_the_bin_is_empty(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--sim", "--bin-parts", "3", "--bin-seed", "4", "--speed", SPEED,
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    records = journal_of(journal)
    branches = [(r["step"], r["outcome"], r["branch"]) for r in records if r["kind"] == "branch"]
    assert branches == [(1, "PartFound", "PartFound"), (5, "PartFound", "PartFound"), (5, "PartFound", "PartFound"),
                        (5, "BinEmpty", "NoPartFound")]
    last = [r for r in records if r["kind"] == "step"][-1]
    assert (last["step"], last["command"]) == (8, "move-to")
    home = [r for r in records if r["kind"] == "command" and r["device"] == "robot"][-1]
    assert home["command"] == "MoveTo" and home["params"]["TargetPose"] == [0.3, 0.0, 0.4, 0, 180, 0]
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "succeeded"


def test_the_report_says_which_branch_each_step_took(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    assert pnp("run", str(TASK), "--sim", "--bin-parts", "0", "--journal", str(journal)).returncode == 0
    report = pnp("report", str(journal)).stdout
    assert "step 1 reported BinEmpty: the task takes branch NoPartFound at step 1" in report
    assert "step 2: pick" not in report and "status: succeeded" in report
