"""A repaired task as the user reads it: plain YAML (no anchors), its ``repeat`` kept."""

from __future__ import annotations

from pathlib import Path

import yaml
from typer.testing import CliRunner

from plugnproduce.cli import app
from tests.reasoning.conftest import BIN_PICKING

TASK = """task: place-twice
repeat: 2
steps:
  - command: place
    params:
      place_pose: [0.6, -0.2, 0.1, 0, 180, 0]
"""


def _repaired(tmp_path: Path) -> str:
    task = tmp_path / "task.yaml"
    task.write_text(TASK)
    result = CliRunner().invoke(app, ["repair", str(task), "--cell", str(BIN_PICKING)])
    assert result.exit_code == 0, result.output
    first = result.stdout.split("repair 1 (cost")[1].split("repair 2")[0]
    return first.split("resulting task:\n")[1]


def test_issue_11_repaired_task_has_no_yaml_anchors(tmp_path: Path) -> None:
    text = _repaired(tmp_path)
    assert "&id" not in text and "*id" not in text


def test_issue_11_repaired_task_keeps_repeat(tmp_path: Path) -> None:
    doc = yaml.safe_load(_repaired(tmp_path))
    assert doc["repeat"] == 2
    assert [s["command"] for s in doc["steps"]] == ["close-gripper", "place"]
