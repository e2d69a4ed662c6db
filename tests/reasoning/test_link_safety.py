"""The check proves a value taken from a device's output within the consuming device's contract where the
producing device declares the output's range, and says "checked at run time" for the links it cannot prove."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app

runner = CliRunner()
DATA = Path(__file__).parents[1] / "data" / "libraries"
LIFT = DATA / "relative-lift" / "tasks" / "lift-with-the-part.yaml"
CELL = service.builtin("cells", "bin-picking.yaml")


def test_a_reported_pose_within_the_declared_range_is_proven_within_reach() -> None:
    result = runner.invoke(app, ["check", str(LIFT), "--cell", str(CELL)])
    assert result.exit_code == 0, result.output
    assert ("step 2 (pick): lift_pose from localize.part_pose: proven within the contract (binpicking-pc reports "
            "part_pose within 1.2 m of the base plus an offset of 0.2 m; robot reaches 1.45 m)") in result.stdout
    assert "step 2 (pick): pick_pose from localize.part_pose: proven within the contract" in result.stdout


def test_a_link_from_a_device_that_declares_no_range_is_checked_at_run_time() -> None:
    library = DATA / "far-part"
    result = runner.invoke(app, ["check", str(library / "tasks" / "pick-where-localized.yaml"),
                                 "--cell", str(library / "cells" / "far-part.yaml"), "--json"])
    assert result.exit_code == 0, result.output
    (link,) = json.loads(result.stdout)["links"]
    assert link == {"step": 2, "command": "pick", "parameter": "pick_pose", "source": "localize.part_pose",
                    "device": "robot", "proven": False, "checked": "at run time",
                    "why": "far-localizer declares no range for part_pose"}


def test_an_offset_that_may_lift_beyond_reach_is_left_to_run_time(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(LIFT.read_text(encoding="utf-8").replace("[0, 0, 0.2, 0, 0, 0]", "[0, 0, 0.3, 0, 0, 0]"),
                    encoding="utf-8")
    result = runner.invoke(app, ["check", str(task), "--cell", str(CELL)])
    assert result.exit_code == 0, result.output  # the part may lie near enough: the monitor decides at run time
    assert ("lift_pose from localize.part_pose: checked at run time (binpicking-pc reports part_pose within 1.2 m "
            "of the base plus an offset of 0.3 m, and robot reaches only 1.45 m)") in result.stdout


@pytest.mark.parametrize("reach", ["far", "-1", "nan"])
def test_a_bad_declared_range_is_one_line_at_its_place(tmp_path: Path, reach: str) -> None:
    library = tmp_path / "far-part"
    shutil.copytree(DATA / "far-part", library)
    chart = library / "devices" / "far-localizer.scxml"
    chart.write_text(chart.read_text(encoding="utf-8").replace(
        '<param name="part_pose" expr="part_pose"/>', f'<param name="part_pose" expr="part_pose" pnp:maxReach="{reach}"/>'),
        encoding="utf-8")
    cell = library / "cells" / "far-part.yaml"
    cell.write_text(cell.read_text(encoding="utf-8").replace("../../../../../descriptions",
                                                             str(service.builtin("devices").parent)), encoding="utf-8")
    result = runner.invoke(app, ["check", str(library / "tasks" / "pick-where-localized.yaml"), "--cell", str(cell)])
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"{chart}:19: value part_pose: pnp:maxReach is '{reach}'; expected a finite positive number")
    validated = runner.invoke(app, ["validate", str(library / "devices")])
    assert validated.exit_code == 1 and validated.stdout.startswith(f"{chart}:19: value part_pose: pnp:maxReach")

