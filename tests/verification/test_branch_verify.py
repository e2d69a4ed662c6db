"""``pnp verify`` on tasks with branches: every outcome a step's process declares is explored."""

from __future__ import annotations

from pathlib import Path

from plugnproduce import service
from tests.verification.test_verify import CELL, D, napping_gripper, seeded_cell

THEN_HOME = D / "tasks" / "bin-picking-then-home.yaml"

ONLY_WHEN_EMPTY = """task: only-when-empty
steps:
  - command: localize-part
    on:
      NoPartFound:
        - command: close-gripper
        - command: open-gripper
"""


def test_the_shipped_branching_task_is_proved() -> None:
    result = service.verify(THEN_HOME, CELL)
    assert result.verdict == "proved", result.problem
    assert (result.states, result.transitions) == (2703, 2800)  # both outcomes of each localisation, every round


def test_a_fault_only_the_branch_hits_is_found_though_the_device_model_always_finds_a_part(tmp_path: Path) -> None:
    # the bin-picking PC's chart always reports PartFound; a napping gripper deadlocks only the NoPartFound branch
    cell = seeded_cell(tmp_path, napping_gripper())
    task = tmp_path / "only-when-empty.yaml"
    task.write_text(ONLY_WHEN_EMPTY, encoding="utf-8")
    assert service.check(task, cell).plausible
    result = service.verify(task, cell)
    assert result.verdict == "refuted"
    reported = [t.text for t in result.trace if "reporting" in t.text]
    assert reported and "PartLocalized reporting BinEmpty; sends xirp.request.Close to gripper" in reported[-1]
    assert "refuses xirp.request.Close" in (result.problem or "")
