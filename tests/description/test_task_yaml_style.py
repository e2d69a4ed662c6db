"""Issue 29: a task written back (a repaired task, the HMI's export) is in one block style."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.description.loader import load_task, task_to_yaml

CELL = str(service.builtin("cells", "bin-picking.yaml"))


def test_a_repaired_tasks_steps_are_all_written_in_block_style(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text("task: t\nsteps:\n  - command: close-gripper\n  - command: pick\n"
                    "    params: {grip_force: 40, pick_pose: [0.4, 0.1, 0.2, 0, 180, 0]}\n", encoding="utf-8")
    result = CliRunner().invoke(app, ["repair", str(task), "--cell", CELL, "--top", "1"])
    written = result.stdout.split("resulting task:\n")[1]
    assert written.splitlines() == [
        "    task: t", "    steps:", "    - command: close-gripper", "    - command: open-gripper",
        "    - command: pick", "      params:", "        grip_force: 40", "        pick_pose: [0.4, 0.1, 0.2, 0, 180, 0]"]


def test_loops_and_branches_are_written_in_block_style_and_read_back_the_same(tmp_path: Path) -> None:
    source = tmp_path / "task.yaml"
    source.write_text("task: t\nsteps:\n  - loop: {max: 2, steps: [{command: scan-bin}]}\n"
                      "  - command: pick\n    on: {NoPartFound: [{command: open-gripper}]}\n", encoding="utf-8")
    text = task_to_yaml(load_task(source))
    assert "{" not in text, text
    again = tmp_path / "again.yaml"
    again.write_text(text, encoding="utf-8")
    assert task_to_yaml(load_task(again)) == text
