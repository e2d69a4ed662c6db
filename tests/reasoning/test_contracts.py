"""Argument contracts: quantities with units, the limits of a device (built-in and from a user's library)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.description.model import Cell
from tests.conftest import edit
from tests.reasoning.conftest import BIN_PICKING, DESCRIPTIONS, write

LIBRARY = Path(__file__).parent.parent / "data" / "libraries" / "adaptive-gripper"
ASSEMBLY = DESCRIPTIONS / "cells" / "assembly.yaml"


def _pick(tmp_path: Path, grip_force: str, name: str = "task.yaml") -> Path:
    return write(tmp_path, name, f"task: t\nsteps:\n  - command: pick\n    params: {{grip_force: {grip_force}}}\n")


def _codes(task: Path, cell: Path | Cell) -> list[tuple[str, str | None]]:
    return [(p.kind, p.parameter) for p in service.check(task, cell).problems]


def test_the_same_force_in_two_units_gets_the_same_answer(tmp_path: Path) -> None:
    newtons, kilonewtons = _pick(tmp_path, "120 N", "n.yaml"), _pick(tmp_path, "0.12 kN", "kn.yaml")
    first, second = service.check(newtons, BIN_PICKING), service.check(kilonewtons, BIN_PICKING)
    assert [p.text for p in first.problems] == [p.text for p in second.problems]
    assert [p.kind for p in first.problems] == ["device_limit"]  # the gripper takes at most 100 N


def test_a_force_with_a_unit_within_the_limits_is_plausible(tmp_path: Path) -> None:
    assert service.check(_pick(tmp_path, "0.05 kN"), BIN_PICKING).plausible


@pytest.mark.parametrize("value, needle", [
    ("12 kg", "kg cannot be converted to N"),
    ("3 parsecs", "cannot be converted to N"),
])
def test_a_quantity_that_is_no_force_is_a_finding_at_its_line(tmp_path: Path, value: str, needle: str) -> None:
    task = _pick(tmp_path, f"'{value}'")
    result = CliRunner().invoke(app, ["check", str(task), "--cell", str(BIN_PICKING)])
    assert result.exit_code == 1
    assert f"{task}:4: step 1 (pick): parameter grip_force is '{value}'; " in result.stdout
    assert needle in result.stdout


def test_a_word_is_still_a_type_finding(tmp_path: Path) -> None:
    assert _codes(_pick(tmp_path, "firm"), BIN_PICKING) == [("bad_type", "grip_force")]


def test_a_pose_beyond_the_robots_reach_is_a_finding(tmp_path: Path) -> None:
    task = write(tmp_path, "task.yaml", "task: t\nsteps:\n  - command: move-to\n"
                 "    params: {target_pose: [1.2, 1.0, 0.3, 0, 180, 0]}\n")
    (p,) = service.check(task, BIN_PICKING).problems
    assert (p.kind, p.device, p.where.line) == ("device_limit", "robot", 4)
    assert "reaches at most 1.45 m from its base" in p.text


def test_issue_12_the_assembly_cells_pick_and_place_is_refused_naming_the_missing_vacuum() -> None:
    result = CliRunner().invoke(app, ["check", str(DESCRIPTIONS / "tasks" / "pick-and-place.yaml"),
                                      "--cell", str(ASSEMBLY), "--verbose"])
    assert result.exit_code == 1
    assert ("device 'vacuum-gripper' cannot play role 'gripper' of pick-and-place: its request SuctionOn needs "
            "the argument vacuum (pnp:Vacuum)") in result.stdout
    assert "vacuum-gripper.ttl:" in result.stdout


def test_capabilities_name_the_device_request_and_argument_a_process_lacks() -> None:
    result = CliRunner().invoke(app, ["capabilities", "--cell", str(ASSEMBLY), "--json"])
    doc = json.loads(result.stdout)
    (entry,) = [n for n in doc["not_offered"] if n["command"] == "pick-and-place"]
    (reason,) = entry["reasons"]
    assert reason["code"] == "no_argument"
    assert "http://plugnproduce.org/ontology#Vacuum" in reason["iris"]
    assert "'vacuum-gripper'" in reason["text"] and "SuctionOn" in reason["text"]


# ------------------------------------------------------------------ a user's library device with its own limits


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    """The adaptive-gripper library, its gripper made to declare its force in kN (at most 60 N)."""
    folder = Path(shutil.copytree(LIBRARY, tmp_path / "adaptive-gripper"))
    ttl = folder / "devices" / "adaptive-gripper.ttl"
    edit(ttl, "pnp:cost 2400 .", "pnp:cost 2400 ;\n    pnp:hasArgument dev:adaptive-gripper-force .\n\n"
         "dev:adaptive-gripper-force a pnp:RequestArgument ;\n    pnp:request \"Close\" ;\n"
         "    pnp:quantity pnp:GripForce ;\n    pnp:unit \"kN\" ;\n    pnp:minValue 0.01 ; pnp:maxValue 0.06 .\n")
    return folder


def _bin_picking(tmp_path: Path, grip_force: object) -> Path:
    text = (DESCRIPTIONS / "tasks" / "bin-picking.yaml").read_text()
    return write(tmp_path, "bin-picking.yaml", text.replace("grip_force: 45", f"grip_force: {grip_force}")
                 .replace("gripper: gripper}", "gripper: adaptive-gripper}"))


def test_a_library_devices_own_limit_in_its_own_unit_refuses_a_value(library: Path, tmp_path: Path) -> None:
    cell = library / "cells" / "bin-picking-adaptive.yaml"
    result = CliRunner().invoke(app, ["check", str(_bin_picking(tmp_path, "70")), "--cell", str(cell), "--verbose"])
    assert result.exit_code == 1
    assert "device 'adaptive-gripper' with request Close, which takes at most 0.06 kN; the value is 70 N" \
        in result.stdout
    assert f"{library / 'devices' / 'adaptive-gripper.ttl'}:16" in result.stdout  # the argument's own line


def test_a_library_device_is_sent_the_value_in_its_own_unit(library: Path, tmp_path: Path) -> None:
    cell = library / "cells" / "bin-picking-adaptive.yaml"
    k = service.knowledge_for_cell(cell)
    generated = service.generate(_bin_picking(tmp_path, "'45 N'"), cell, knowledge=k)
    task_chart = next(c for c in generated.charts if c.name.endswith(".scxml") and "task" in c.name)
    assert b'name="GripForce" expr="0.045"' in task_chart.data
