"""The run-time monitor: no argument beyond the bound device's contract ever leaves the controller."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.executor.monitor import Breach, Monitor

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "far-part"
TASK = LIBRARY / "tasks" / "pick-where-localized.yaml"
REACH = 1.45  # the robot's pnp:maxReach


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)


def journal_of(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def test_a_pose_reported_beyond_reach_ends_the_run_before_the_robot_is_sent_there(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--cell", str(LIBRARY / "cells" / "far-part.yaml"), "--sim",
                 "--journal", str(journal))
    assert result.returncode == 1, result.stdout[-2000:] + result.stderr
    assert "fault: contract at step 2 (pick), device robot in state home, request MoveTo" in result.stdout
    assert "(part_pose reported by far-localizer at step 1)" in result.stdout
    assert "reaches at most 1.45 m from its base; the pose is 5 m away" in result.stdout
    records = journal_of(journal)
    moves = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r["command"] == "MoveTo"]
    assert all(math.dist(pose[:3], (0, 0, 0)) <= REACH for pose in moves)  # nothing beyond the reach went out
    kinds = [r["kind"] for r in records]
    assert "state" not in kinds[kinds.index("fault"):]  # no "robot is moving": the MoveTo was never sent
    (fault,) = [r for r in records if r["kind"] == "fault"]
    assert (fault["fault"], fault["step"], fault["device"], fault["request"], fault["argument"]) == \
        ("contract", 2, "robot", "MoveTo", "TargetPose")
    assert [r["kind"] for r in records][-1] == "end" and records[-1]["outcome"] == "failed"
    assert {r["device"] for r in records if r["kind"] == "stop"} == {"robot", "gripper", "sensor3d", "far-localizer"}


def test_a_huge_string_reported_as_a_pose_is_never_sent(tmp_path: Path) -> None:
    library = tmp_path / "far-part"
    shutil.copytree(LIBRARY, library)
    chart = library / "devices" / "far-localizer.scxml"
    chart.write_text(chart.read_text(encoding="utf-8").replace(
        'expr="[5.0, 0, 0.05, 0, 180, 0]"', "expr=\"'x' * 60000\""), encoding="utf-8")
    cell = library / "cells" / "far-part.yaml"
    cell.write_text(cell.read_text(encoding="utf-8").replace("../../../../../descriptions",
                                                             str(service.builtin("devices").parent)), encoding="utf-8")
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(library / "tasks" / "pick-where-localized.yaml"), "--cell", str(cell), "--sim",
                 "--journal", str(journal))
    assert result.returncode == 1, result.stdout[-2000:] + result.stderr
    assert "takes at most 1024 characters; the value has 60,000" in result.stdout
    records = journal_of(journal)
    assert not any(len(json.dumps(r["params"])) > 1024 for r in records if r["kind"] == "command")


@pytest.fixture(scope="module")
def monitor() -> Monitor:
    return Monitor(service.generate(service.builtin("tasks", "bin-picking.yaml"),
                                    service.builtin("cells", "bin-picking.yaml")).task,
                   service.cell(service.builtin("cells", "bin-picking.yaml")))


@pytest.mark.parametrize(("params", "why"), [
    ({"GripForce": "lots"}, "takes a number; the value is 'lots'"),
    ({"GripForce": 130}, "takes at most 100 N; the value is 130 N"),
    ({"GripForce": float("inf")}, "takes a finite number"),
    ({"GripForce": [45] * 100}, "takes at most 64 items"),
    ({}, "requires it; the request lacks it"),
])
def test_each_argument_is_held_to_the_contract_whatever_it_is(monitor: Monitor, params: dict[str, Any],
                                                             why: str) -> None:
    result = monitor.check(1, "gripper", "Close", params, {})
    assert isinstance(result, Breach) and result.argument == "GripForce"
    assert why in result.why
    assert result.source.startswith("the task's value of grip_force at step 1, ")


def test_an_argument_within_the_contract_goes_out_as_given(monitor: Monitor) -> None:
    assert monitor.check(1, "gripper", "Close", {"GripForce": 45}, {}) == {"GripForce": 45}


def test_a_value_that_varies_between_steps_goes_out_in_the_devices_unit(tmp_path: Path) -> None:
    """Picks 2 and 3 share one chart with different forces: the chart carries them in the process's unit (N), the
    library's gripper takes kN; each goes out converted and within its limits, never as 50 kN."""
    library = Path(shutil.copytree(LIBRARY.parent / "adaptive-gripper", tmp_path / "adaptive-gripper"))
    ttl = library / "devices" / "adaptive-gripper.ttl"
    ttl.write_text(ttl.read_text(encoding="utf-8").replace(
        "pnp:cost 2400 .", "pnp:cost 2400 ;\n    pnp:hasArgument dev:adaptive-gripper-force .\n\n"
        "dev:adaptive-gripper-force a pnp:RequestArgument ;\n    pnp:request \"Close\" ;\n"
        "    pnp:quantity pnp:GripForce ;\n    pnp:unit \"kN\" ;\n    pnp:minValue 0.01 ; pnp:maxValue 0.06 .\n"),
        encoding="utf-8")
    task = tmp_path / "three-forces.yaml"
    task.write_text("task: three-forces\nsteps:\n  - command: bin-pick\n    bind: {robot: robot, gripper: adaptive-gripper}\n"
                    "    params: {grip_force: 45}\n  - command: place\n  - command: bin-pick\n"
                    "    params: {grip_force: 50}\n  - command: place\n  - command: bin-pick\n"
                    "    params: {grip_force: 55}\n  - command: place\n", encoding="utf-8")
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(task), "--cell", str(library / "cells" / "bin-picking-adaptive.yaml"), "--sim",
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    forces = [r["params"]["GripForce"] for r in journal_of(journal) if r["kind"] == "command" and r["command"] == "Close"]
    assert forces == pytest.approx([0.045, 0.05, 0.055])
