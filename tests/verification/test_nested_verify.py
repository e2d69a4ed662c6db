"""``pnp verify`` on a task with a loop inside a loop: every interleaving and every way out is explored."""

from __future__ import annotations

import subprocess
import sys

from plugnproduce import service
from tests.verification.test_verify import CELL, D

ROUNDS = D / "tasks" / "bin-picking-in-rounds.yaml"


def test_the_shipped_nested_task_is_proved() -> None:
    result = service.verify(ROUNDS, CELL)
    assert result.verdict == "proved", result.problem


def test_pnp_verify_proves_the_nested_task_on_the_bin_picking_cell() -> None:
    done = subprocess.run([sys.executable, "-m", "plugnproduce", "verify", str(ROUNDS), "--cell", str(CELL)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "proved" in done.stdout and "every interleaving reaches done" in done.stdout
