"""Every bound, exactly at it and one step over, as ``pnp check`` answers: the minimum and maximum of a process
parameter (rules/params.lp) and of a device's own limits (its ``pnp:RequestArgument``, and a robot's reach),
with values written as plain numbers and with units, and a device whose limits are in another unit than the
process's. Values are compared in thousandths, so one step over is 0.001 (of the parameter's unit)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app

LIBRARIES = Path(__file__).parent.parent / "data" / "libraries"
BIN_PICKING = service.builtin("cells", "bin-picking.yaml")
ASSEMBLY = service.builtin("cells", "assembly.yaml")
ADAPTIVE = LIBRARIES / "adaptive-gripper" / "cells" / "bin-picking-adaptive.yaml"  # no limits of its own
KILONEWTON = LIBRARIES / "kilonewton-gripper" / "cells" / "bin-picking-kn.yaml"  # limits in kN
POSE = "[0.40, 0.10, 0.30, 0, 180, 0]"

BOUNDS = [
    # (what, cell, command, parameter, at the bound, one step over, the finding over it)
    ("parameter min", ADAPTIVE, "close-gripper", "grip_force", "10", "9.999", "too_low"),
    ("parameter max", ADAPTIVE, "close-gripper", "grip_force", "140", "140.001", "too_high"),
    ("parameter min, kN", ADAPTIVE, "close-gripper", "grip_force", "0.01 kN", "0.009999 kN", "too_low"),
    ("parameter max, kN", ADAPTIVE, "close-gripper", "grip_force", "0.14 kN", "140.001 N", "too_high"),
    ("parameter min, %", BIN_PICKING, "move-to", "speed", "1 %", "0.999 %", "too_low"),
    ("parameter max", BIN_PICKING, "move-to", "speed", "100", "100.001", "too_high"),
    ("parameter min", ASSEMBLY, "screw", "torque", "0.5", "0.499", "too_low"),
    ("parameter min, N mm", ASSEMBLY, "screw", "torque", "500 N mm", "499 N mm", "too_low"),
    ("device min", BIN_PICKING, "close-gripper", "grip_force", "20", "19.999", "device_limit"),
    ("device max", BIN_PICKING, "close-gripper", "grip_force", "100", "100.001", "device_limit"),
    ("device min, kN", BIN_PICKING, "close-gripper", "grip_force", "0.02 kN", "0.019999 kN", "device_limit"),
    ("device max, s", BIN_PICKING, "scan-bin", "exposure", "0.15 s", "0.150001 s", "device_limit"),
    ("device max", BIN_PICKING, "scan-bin", "exposure", "150", "150.001", "device_limit"),
    ("device min", ASSEMBLY, "transport", "belt_speed", "5", "4.999", "device_limit"),
    ("device max", ASSEMBLY, "move-to", "speed", "60", "60.001", "device_limit"),
    ("device max, N mm", ASSEMBLY, "screw", "torque", "10000 N mm", "10001 N mm", "device_limit"),
    ("device min in kN, N", KILONEWTON, "close-gripper", "grip_force", "25", "24.999", "device_limit"),
    ("device max in kN, kN", KILONEWTON, "close-gripper", "grip_force", "0.08 kN", "80.001 N", "device_limit"),
    ("device reach", BIN_PICKING, "move-to", "target_pose", "[1.45, 0, 0, 0, 180, 0]", "[1.451, 0, 0, 0, 180, 0]",
     "device_limit"),
]

OTHERS = {"move-to": {"target_pose": POSE}}
"""Values a command needs besides the one at its bound."""


def check(tmp_path: Path, cell: Path, command: str, parameter: str, value: str) -> tuple[int, dict]:
    """``pnp check --json`` of a one-step task with ``parameter`` written on line 5; its exit code and answer."""
    others = {k: v for k, v in OTHERS.get(command, {}).items() if k != parameter}
    lines = ["task: bound", "steps:", f"  - command: {command}", "    params:", f"      {parameter}: {value}",
             *(f"      {k}: {v}" for k, v in others.items())]
    task = tmp_path / f"{command}.yaml"
    task.write_text("\n".join(lines) + "\n", encoding="utf-8")
    libraries = [a for lib in (LIBRARIES / "adaptive-gripper", LIBRARIES / "kilonewton-gripper")
                 if lib in cell.parents for a in ("--library", str(lib))]
    result = CliRunner().invoke(app, [*libraries, "check", str(task), "--cell", str(cell), "--json"])
    assert result.exit_code in (0, 1), result.output
    return result.exit_code, json.loads(result.stdout)


@pytest.mark.parametrize(("what", "cell", "command", "parameter", "at", "over", "kind"), BOUNDS,
                         ids=[f"{b[0]}: {b[2]} {b[3]}" for b in BOUNDS])
def test_a_value_exactly_at_a_bound_is_accepted_and_one_step_over_it_is_refused_at_its_line(
        tmp_path: Path, what: str, cell: Path, command: str, parameter: str, at: str, over: str, kind: str) -> None:
    code, answer = check(tmp_path, cell, command, parameter, at)
    assert (code, answer["plausible"], answer["problems"]) == (0, True, [])
    code, answer = check(tmp_path, cell, command, parameter, over)
    assert (code, answer["plausible"]) == (1, False)
    assert [(p["kind"], p["parameter"], p["where"]) for p in answer["problems"]] == [
        (kind, parameter, f"{tmp_path / command}.yaml:5")]
