"""A parameter value no bound device accepts is a check finding, not a value lost at run time."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.description.model import DeviceDescription
from tests.reasoning.conftest import DESCRIPTIONS, write


def _vacuum_cell(tmp_path: Path, vacuum: DeviceDescription) -> Path:
    """A robot and a vacuum gripper that has a default vacuum (so that it can close)."""
    devices = f"  - {DESCRIPTIONS / 'devices' / 'robot.ttl'}\n  - {vacuum.where.file}\n"
    return write(tmp_path, "cell.yaml", f"cell: vacuum\ndevices:\n{devices}")


def test_issue_11_grip_force_for_a_vacuum_gripper_is_a_finding(tmp_path: Path,
                                                               vacuum_with_default: DeviceDescription) -> None:
    task = write(tmp_path, "task.yaml", "task: t\nsteps:\n  - command: close-gripper\n    params: {grip_force: 50}\n")
    cell = _vacuum_cell(tmp_path, vacuum_with_default)
    result = CliRunner().invoke(app, ["check", str(task), "--cell", str(cell)])
    assert result.exit_code == 1
    assert f"{task}:4: step 1 (close-gripper): parameter grip_force" in result.stdout
    assert "device 'vacuum-gripper'" in result.stdout and "accepts grip force" in result.stdout


def test_a_parameter_left_to_its_default_is_no_finding(tmp_path: Path,
                                                       vacuum_with_default: DeviceDescription) -> None:
    task = write(tmp_path, "task.yaml", "task: t\nsteps:\n  - command: close-gripper\n")
    assert service.check(task, _vacuum_cell(tmp_path, vacuum_with_default)).plausible


def test_parameters_the_devices_accept_are_no_finding() -> None:
    result = service.check(DESCRIPTIONS / "tasks" / "bin-picking.yaml", DESCRIPTIONS / "cells" / "bin-picking.yaml")
    assert result.plausible and not result.problems
