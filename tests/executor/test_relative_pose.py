"""Relative poses: a link may add an offset to a pose (the lift after a pick follows the part), held to the
device's limits like every other value."""

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
from plugnproduce.description.model import Link

DATA = Path(__file__).parents[1] / "data" / "libraries"
TASK = DATA / "relative-lift" / "tasks" / "lift-with-the-part.yaml"
CELL = service.builtin("cells", "bin-picking.yaml")
REACH = 1.45


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)


def journal_of(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def test_the_lift_follows_each_part_found(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--cell", str(CELL), "--sim", "--bin-parts", "2", "--bin-seed", "3",
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    records = journal_of(journal)
    found = [r["produced"] for r in records if r["kind"] == "value" and "produced" in r
             and r["value"] == "localize.part_pose"]
    moves = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r["command"] == "MoveTo"]
    picks_and_lifts = [moves[i:i + 2] for i in range(0, len(moves), 4)]  # pick, lift, place, away
    assert len(found) >= 2 and len(picks_and_lifts) == 2
    for part, (pick, lift) in zip(found, picks_and_lifts, strict=False):
        assert pick == part
        assert lift == pytest.approx([v + o for v, o in zip(part, [0, 0, 0.2, 0, 0, 0], strict=True)])


def test_a_lift_beyond_reach_is_a_fault_though_the_part_is_within_it(tmp_path: Path) -> None:
    library = tmp_path / "far-part"
    shutil.copytree(DATA / "far-part", library)
    chart = library / "devices" / "far-localizer.scxml"
    chart.write_text(chart.read_text(encoding="utf-8").replace("[5.0, 0, 0.05, 0, 180, 0]", "[1.3, 0, 0.05, 0, 180, 0]"),
                     encoding="utf-8")
    task = library / "tasks" / "pick-where-localized.yaml"
    task.write_text(task.read_text(encoding="utf-8").replace(
        "      grip_force: 45", "      lift_pose: {from: localize, output: part_pose, offset: [0, 0, 0.8, 0, 0, 0]}\n"
                                "      grip_force: 45"), encoding="utf-8")
    cell = library / "cells" / "far-part.yaml"
    cell.write_text(cell.read_text(encoding="utf-8").replace("../../../../../descriptions",
                                                             str(service.builtin("devices").parent)), encoding="utf-8")
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(task), "--cell", str(cell), "--sim", "--journal", str(journal))
    assert result.returncode == 1, result.stdout[-2000:] + result.stderr
    assert ("(part_pose reported by far-localizer at step 1 plus the offset [0.0, 0.0, 0.8, 0.0, 0.0, 0.0]) is "
            "beyond the contract of robot, which reaches at most 1.45 m from its base") in result.stdout
    moves = [r["params"]["TargetPose"] for r in journal_of(journal) if r["kind"] == "command" and r["command"] == "MoveTo"]
    assert moves == [[1.3, 0, 0.05, 0, 180, 0]]  # the pick went out; the lift beyond reach did not
    assert all(math.dist(m[:3], (0, 0, 0)) <= REACH for m in moves)


@pytest.mark.parametrize(("offset", "why"), [
    ("[0, 0, 0.2]", "an offset is a pose's change [x, y, z, rx, ry, rz]"),
    ("[0, 0, x, 0, 0, 0]", "an offset is a pose's change [x, y, z, rx, ry, rz]"),
    ("0.2", "an offset is a pose's change [x, y, z, rx, ry, rz]"),
    ("[0, 0, .nan, 0, 0, 0]", "not a number a device can be given"),
    ("[0, 0, 1" + "0" * 400 + ", 0, 0, 0]", "an integer of 401 digits"),
])
def test_a_bad_offset_is_one_line_at_its_place(tmp_path: Path, offset: str, why: str) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(TASK.read_text(encoding="utf-8").replace("[0, 0, 0.2, 0, 0, 0]", offset), encoding="utf-8")
    result = pnp("check", str(task), "--cell", str(CELL))
    assert result.returncode == 2, result.stdout + result.stderr
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"{task}:20: ") and why in line


def test_an_offset_on_an_output_that_is_no_pose_is_a_finding(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(TASK.read_text(encoding="utf-8").replace("          params:\n            place_pose: [0.60, -0.20, 0.10, 0, 180, 0]",
                                 "          params:\n            place_pose: {from: localize, output: part_type, "
                                 "offset: [0, 0, 0.2, 0, 0, 0]}"), encoding="utf-8")
    result = pnp("check", str(task), "--cell", str(CELL), "--json")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "with an offset, but part_type is a string; only a pose takes an offset" in result.stdout


def test_a_link_with_an_offset_is_written_back_as_it_was_read() -> None:
    link = Link("localize", "part_pose", (0.0, 0.0, 0.2, 0.0, 0.0, 0.0))
    assert link.to_plain() == {"from": "localize", "output": "part_pose", "offset": [0.0, 0.0, 0.2, 0.0, 0.0, 0.0]}
    assert link.applied([0.4, 0.1, 0.05, 0, 180, 0]) == pytest.approx([0.4, 0.1, 0.25, 0, 180, 0])
    assert link.applied("not a pose") == "not a pose"
