"""``pnp plan``: a goal becomes a task that the check accepts, verification proves and the simulated cell runs."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.description.goalfile import Goal, parse_goal
from plugnproduce.description.model import Cell, Link
from plugnproduce.planning import Plan, Unreachable
from plugnproduce.sim.bin import SimulatedBin
from plugnproduce.verification import PROVED

CELL = service.builtin("cells", "bin-picking.yaml")
EMPTY_THE_BIN = service.builtin("goals", "empty-the-bin.yaml")
MACHINE_TENDING = Path(__file__).parents[1] / "data" / "libraries" / "machine-tending"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)


def goal_file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "goal.yaml"
    path.write_text(text)
    return path


def planned(goal: Path | Goal, cell: Path | Cell = CELL) -> Plan:
    found = service.plan(goal, cell)
    assert isinstance(found, Plan), found
    return found


def test_the_bin_goal_plans_localize_pick_place_in_a_loop_the_check_accepts_and_verification_proves() -> None:
    found = planned(EMPTY_THE_BIN)
    loop, = found.task.loops
    assert loop.until.endswith("#BinEmpty")
    localize, pick, place = found.task.one_round()[:found.steps]
    assert [s.command for s in (localize, pick, place)] == ["localize-part", "pick", "place"]
    assert pick.params == {"pick_pose": Link(localize.name or "", "part_pose")}  # the pose the PC reports
    assert place.params == {"place_pose": [0.60, -0.20, 0.10, 0, 180, 0]}  # the value the goal fixes
    assert found.blind == ((1, "part_type"),)  # the one value left to its default that the cell could measure
    assert service.check(found.task, CELL).plausible
    assert service.verify(found.task, CELL).verdict == PROVED


def test_the_planned_task_empties_a_seeded_bin_picking_each_part_where_the_pc_found_it(tmp_path: Path) -> None:
    task, journal = tmp_path / "empty.yaml", tmp_path / "run.jsonl"
    done = pnp("plan", str(EMPTY_THE_BIN), "--cell", str(CELL), "-o", str(task))
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"written to {task}" in done.stdout
    ran = pnp("run", str(task), "--sim", "--bin-parts", "3", "--bin-seed", "7", "--journal", str(journal))
    assert ran.returncode == 0, ran.stdout[-2000:] + ran.stderr
    records: list[dict[str, Any]] = [json.loads(line) for line in journal.read_text().splitlines()]
    found = [r for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert [r["params"]["outcome"] for r in found] == ["PartFound"] * 3 + ["BinEmpty"]
    for reported in found[:-1]:
        move = next(r for r in records[records.index(reported):] if r["kind"] == "command" and r["device"] == "robot")
        assert move["command"] == "MoveTo" and move["params"]["TargetPose"] == reported["params"]["part_pose"]
    assert sorted(r["params"]["part_pose"] for r in found[:-1]) == sorted(p.pose for p in SimulatedBin(3, 7).parts)
    assert records[-1]["outcome"] == "succeeded"


def test_a_screwing_goal_says_what_is_missing_and_what_to_buy(tmp_path: Path) -> None:
    goal = goal_file(tmp_path, "goal: fasten\nachieve:\n  - command: screw\n")
    done = pnp("plan", str(goal), "--cell", str(CELL))
    assert done.returncode == 1
    assert "screw is not offered: role 'screwdriver' of screw needs a device that can screw" in done.stdout
    assert "buy screwdriver (Electric screwdriver, cost 1400) from the catalogue" in done.stdout
    answer = json.loads(pnp("plan", str(goal), "--cell", str(CELL), "--json").stdout)
    assert answer["reachable"] is False and answer["purchase"]["device"] == "screwdriver"


def test_end_states_are_reached_and_the_goals_commands_run_in_order(tmp_path: Path) -> None:
    goal = goal_file(tmp_path, "goal: park\nachieve:\n  - command: place\n  - command: move-to\n"
                               "end: {gripper: Closed}\n")
    found = planned(goal)
    commands = [s.command for s in found.task.steps]
    assert commands.index("place") < commands.index("move-to")
    checked = service.check(found.task, CELL)
    assert checked.plausible and checked.final_states["gripper"] == "closed"


def test_a_plan_starts_where_the_devices_are() -> None:
    # place needs the gripper closed: from the chart's initial state (open) a step must close it first;
    # from a gripper that reports closed, place alone reaches the goal
    drop = parse_goal(b"goal: drop\nachieve:\n  - command: place\n", "drop.yaml")
    cell = service.cell(CELL)
    assert [s.command for s in planned(drop, cell).task.steps][1:] == ["place"]
    assert [s.command for s in planned(drop, cell.reported({"gripper": "closed"})).task.steps] == ["place"]


def test_a_library_outside_the_package_plans_its_own_processes(tmp_path: Path) -> None:
    goal = goal_file(tmp_path, "goal: one-part\nachieve:\n  - command: machine\n    params: {nc_program: O2001}\n"
                               "  - command: unload-machine\nend: {mt-cnc: DoorClosed}\n")
    cell = MACHINE_TENDING / "cells" / "machine-tending.yaml"
    found = planned(goal, cell)
    assert [s.command for s in found.task.steps] == ["open-door", "load-machine", "close-door", "machine",
                                                     "open-door", "unload-machine", "close-door"]
    assert service.check(found.task, cell).plausible


def test_an_outcome_no_offered_command_reports_is_unreachable(tmp_path: Path) -> None:
    goal = goal_file(tmp_path, "goal: g\nachieve:\n  - command: move-to\nuntil: BinEmpty\n")
    cell = MACHINE_TENDING / "cells" / "machine-tending.yaml"
    found = service.plan(goal, cell)
    assert isinstance(found, Unreachable)
    assert "no command the cell offers reports BinEmpty" in found.reasons


@pytest.mark.parametrize(("text", "line", "message"), [
    ("goal: g\nachieve:\n  - command: plase\n", 3, "unknown process command 'plase'; did you mean place?"),
    ("goal: g\nachieve:\n  - command: place\n    params: {speeed: 3}\n", 3, "place has no parameter 'speeed'"),
    ("goal: g\nachieve:\n  - command: place\nend: {griper: Open}\n", 4, "the cell has no device 'griper'"),
    ("goal: g\nachieve:\n  - command: place\nuntil: BinFull\n", 4, "until: unknown outcome 'BinFull'"),
    ("goal: g\nachieve: []\n", 2, "achieve must be a list of 1 to 50 commands"),
    ("goal: g\nachieve:\n  - command: pick\n    params: {pick_pose: {from: a, output: b}}\n", 3,
     "which step's output a parameter takes is the planner's choice"),
])
def test_a_bad_goal_is_one_line_at_its_line_and_exit_2(tmp_path: Path, text: str, line: int, message: str) -> None:
    goal = goal_file(tmp_path, text)
    done = pnp("plan", str(goal), "--cell", str(CELL))
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith(f"{goal}:{line}: ") and message in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(("params", "found"), [
    ("{place_pose: [9.6, -0.2, 0.1, 0, 180, 0]}", "which reaches at most 1.45 m from its base; the pose is 9.6 m away"),
    ("{place_pose: [0.6, -0.2, 0.1, 0, 180, 0], speed: 500}", "parameter speed = 500 % is above its maximum 100 %"),
    ('{place_pose: "0.6 -0.2 far"}', "parameter place_pose is not a pose value"),
])
def test_a_goal_fixing_a_value_beyond_a_limit_is_exit_1_at_its_line_and_writes_no_task(
        tmp_path: Path, params: str, found: str) -> None:
    goal = goal_file(tmp_path, f"goal: g\nachieve:\n  - command: place\n    params: {params}\n")
    task = tmp_path / "task.yaml"
    done = pnp("plan", str(goal), "--cell", str(CELL), "-o", str(task))
    assert done.returncode == 1, done.stdout + done.stderr
    assert "the check finds it implausible" in done.stdout
    assert f"{goal}:3: step 2 (place): " in done.stdout and found in done.stdout
    assert not task.exists()
    answer = pnp("plan", str(goal), "--cell", str(CELL), "--json")
    assert answer.returncode == 1 and json.loads(answer.stdout)["check"]["plausible"] is False


def test_validate_reads_goal_files_and_names_an_unknown_command_at_its_line(tmp_path: Path) -> None:
    assert pnp("validate", str(service.builtin("goals"))).returncode == 0
    goal = goal_file(tmp_path, "goal: g\nachieve:\n  - command: plase\n")
    done = pnp("validate", str(goal))
    assert done.returncode == 1 and f"{goal}:3: unknown process command 'plase'; did you mean place?" in done.stdout
