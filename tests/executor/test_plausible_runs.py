"""The contract test: "plausible" is a promise that the task runs.

Every shipped task on every shipped cell: where ``check`` calls it plausible, ``pnp run --sim``
must end ``succeeded``; a plausible task that fails to run is a test failure. Where it is not
plausible, ``pnp run`` refuses it before any command goes out. A task with loops runs on a
simulated bin of a few parts, as in a real cell: its loops end when the bin is empty (without a
bin the simulated localiser finds a part every time, and the loops run to their maximum).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from plugnproduce import service

CELLS = sorted(service.builtin("cells").glob("*.yaml"))
TASKS = sorted(service.builtin("tasks").glob("*.yaml"))
PAIRS = [(c, t) for c in CELLS for t in TASKS]


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("cell, task", PAIRS, ids=[f"{c.stem}-{t.stem}" for c, t in PAIRS])
def test_a_shipped_task_runs_on_a_shipped_cell_if_and_only_if_check_calls_it_plausible(
        cell: Path, task: Path, tmp_path: Path) -> None:
    plausible = service.check(task, cell).plausible
    journal = tmp_path / "run.jsonl"
    parts = ["--bin-parts", "2", "--bin-seed", "1"] if service.task(task).loops else []
    result = pnp("run", str(task), "--cell", str(cell), "--sim", "--journal", str(journal), *parts)
    if plausible:
        assert result.returncode == 0, result.stdout + result.stderr
        assert result.stdout.rstrip().splitlines()[-1] == f"succeeded; journal {journal}"
        assert "end: succeeded" in pnp("report", str(journal)).stdout
    else:
        assert result.returncode == 1
        assert "not plausible" in result.stderr and "→" not in result.stdout


def test_the_contract_test_has_plausible_pairs_to_run() -> None:
    plausible = [(c.stem, t.stem) for c, t in PAIRS if service.check(t, c).plausible]
    assert ("bin-picking", "bin-picking") in plausible and ("bin-picking", "pick-and-place") in plausible
    assert ("assembly", "pick-and-place") not in plausible  # its vacuum gripper lacks a vacuum to use
