"""Repairs of tasks with loops and branches come back as the user wrote the task: the loop (its ``until`` and
``max``) and the branches kept, the edits in the loop's body or the branch's steps, and the result plausible on
every path; a repair the written task cannot hold keeps its flat steps and says so."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.description.model import Task
from plugnproduce.description.taskfile import parse_task
from plugnproduce.reasoning import AssessedRepair, Repair
from plugnproduce.reasoning.repairs.lifting import UNROLLS
from tests.reasoning.conftest import BIN_PICKING, DESCRIPTIONS, TASKS
from tests.reasoning.test_nested_loop_check import REGRIP

UNTIL_EMPTY = (TASKS / "bin-picking-until-empty.yaml").read_text(encoding="utf-8")
NO_PLACE = UNTIL_EMPTY[: UNTIL_EMPTY.index("        - command: place")]  # the body never lets the part go
CLOSED_FIRST = UNTIL_EMPTY.replace("steps:\n  - loop:", "steps:\n  - command: close-gripper\n"
                                   "    bind: {gripper: gripper}\n  - loop:")
PICK = """          params:
            pick_pose: {from: localize, output: part_pose}
            grip_force: 45
"""
TWO_PICKS_IN_A_BRANCH = f"""task: branch-then-scan
steps:
  - name: localize
    command: localize-part
    params: {{exposure: 25}}
    on:
      PartFound:
        - command: pick
{PICK}        - command: pick
{PICK}        - command: place
      NoPartFound:
        - command: move-to
          params:
            target_pose: [0.30, 0.00, 0.40, 0, 180, 0]
  - command: scan-bin
"""
LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "part-finding"


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "task.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _repair(repairs: list[Repair], text: str) -> Repair:
    return next(r for r in repairs if [e.text for e in r.edits] == [text])


def _commands(task: Task, first: int, last: int) -> list[str]:
    return [s.command for s in task.steps[first - 1:last]]


def test_a_step_inserted_in_a_loop_body_keeps_the_loop(tmp_path: Path) -> None:
    path = _file(tmp_path, NO_PLACE)
    # inserting the place before step 3 or before step 4 costs the same: which comes first is the solver's choice
    r = _repair(service.repair(path, BIN_PICKING, top=5), "insert place before step 3 (localize-part)")
    assert r.unrolls is None
    [loop] = r.task.loops
    assert (loop.until or "").endswith("#BinEmpty") and loop.max == 100
    assert _commands(r.task, loop.entry, loop.first - 1) == ["localize-part", "pick", "place"]
    assert service.check(r.task, BIN_PICKING).plausible


def test_a_step_inserted_before_a_loop_goes_before_the_loop(tmp_path: Path) -> None:
    path = _file(tmp_path, CLOSED_FIRST)
    r = _repair(service.repair(path, BIN_PICKING), "insert open-gripper before step 2 (localize-part)")
    assert r.unrolls is None
    [loop] = r.task.loops
    assert _commands(r.task, 1, loop.entry - 1) == ["close-gripper", "open-gripper"]
    assert _commands(r.task, loop.entry, loop.first - 1) == ["localize-part", "pick", "place"]
    assert service.check(r.task, BIN_PICKING).plausible


def test_a_step_inserted_in_a_branch_keeps_the_branches(tmp_path: Path) -> None:
    path = _file(tmp_path, TWO_PICKS_IN_A_BRANCH)
    r = _repair(service.repair(path, BIN_PICKING), "insert place before step 3 (pick)")
    assert r.unrolls is None
    found, none = r.task.branches
    assert [found.outcome.rsplit("#")[1], none.outcome.rsplit("#")[1]] == ["PartFound", "NoPartFound"]
    assert _commands(r.task, found.first, found.last) == ["pick", "place", "pick", "place"]
    assert _commands(r.task, none.first, none.last) == ["move-to"]
    assert r.task.steps[-1].command == "scan-bin" and r.task.steps[-1].index not in range(none.first, none.last + 1)
    assert service.check(r.task, BIN_PICKING).plausible


def test_a_repair_the_loop_cannot_hold_keeps_its_flat_steps_and_says_why(tmp_path: Path) -> None:
    path = _file(tmp_path, CLOSED_FIRST)  # opening before the pick of every iteration fails once place opened it
    r = _repair(service.repair(path, BIN_PICKING), "insert open-gripper before step 3 (pick)")
    assert r.unrolls is not None and r.unrolls.startswith("this repair writes the task's loops and branches out")
    assert "not plausible" in r.unrolls
    assert r.task.loops == () and len(r.task.steps) == 8
    assert r.to_json()["unrolls"] is True and r.to_json()["note"] == r.unrolls


def test_pnp_repair_prints_the_resulting_task_with_its_loop(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["repair", str(_file(tmp_path, CLOSED_FIRST)), "--cell", str(BIN_PICKING)])
    assert result.exit_code == 0, result.output
    chunks = result.stdout.split("\nrepair ")[1:]
    kept = next(c for c in chunks if "insert open-gripper before step 2" in c)
    text = kept.split("resulting task:\n")[1]
    assert "note:" not in kept and "- loop:" in text
    task = parse_task("\n".join(line[4:] for line in text.splitlines()).encode(), "repaired.yaml")
    [loop] = task.loops
    assert (loop.until or "").endswith("#BinEmpty") and loop.max == 100
    flagged = next(c for c in chunks if "insert open-gripper before step 3" in c)
    assert "  note: this repair writes the task's loops and branches out step by step" in flagged


def test_pnp_repair_prints_the_resulting_task_with_its_branches(tmp_path: Path) -> None:
    path = _file(tmp_path, TWO_PICKS_IN_A_BRANCH)
    result = CliRunner().invoke(app, ["repair", str(path), "--cell", str(BIN_PICKING), "--json"])
    assert result.exit_code == 0, result.output
    repairs = json.loads(result.stdout)["repairs"]
    inserted = next(r for r in repairs if r["edits"][0]["text"] == "insert place before step 3 (pick)")
    assert inserted["unrolls"] is False and "note" not in inserted
    [localize, scan] = inserted["task"]["steps"]  # the task as its file writes it
    assert [s["command"] for s in localize["on"]["PartFound"]] == ["pick", "place", "pick", "place"]
    assert scan["command"] == "scan-bin"
    text = CliRunner().invoke(app, ["repair", str(path), "--cell", str(BIN_PICKING)]).stdout
    chunk = text.split("insert place before step 3")[1].split("\nrepair ")[0]
    assert "'on':\n        PartFound:" in chunk


@pytest.mark.parametrize(("edit", "kept"), [
    ("insert open-gripper before step 3 (move-to)", True),  # at the end of the PartFound branch
    ("insert open-gripper before step 5 (pick)", False),  # every iteration would open an open gripper
])
def test_a_library_task_with_its_own_outcome_keeps_its_loop_and_branches(tmp_path: Path, edit: str,
                                                                         kept: bool) -> None:
    text = (LIBRARY / "tasks" / "clear-bin-or-look-again.yaml").read_text(encoding="utf-8")
    path = _file(tmp_path, text.replace("              - command: place\n", ""))
    knowledge = service.knowledge((LIBRARY,))
    r = _repair(service.repair(path, BIN_PICKING, knowledge=knowledge), edit)
    assert (r.unrolls is None) == kept
    if kept:
        found = next(b for b in r.task.branches if b.outcome.endswith("#PartFound"))
        assert _commands(r.task, found.first, found.last) == ["pick", "open-gripper"]
        assert len(r.task.loops) == 1 and service.check(r.task, BIN_PICKING, knowledge).plausible
        assert [(lp.entry, lp.first, lp.last) for lp in r.task.loops] == [(1, 5, 8)]
        assert [(b.outcome.rsplit("#")[1], b.step, b.first, b.last) for b in r.task.branches] == [
            ("PartFound", 1, 2, 3), ("PartOccluded", 1, 4, 4), ("PartFound", 5, 6, 7), ("PartOccluded", 5, 8, 8)]


def test_a_loop_long_enough_to_be_repaired_window_by_window_keeps_its_loop(tmp_path: Path) -> None:
    move = "        - command: move-to\n          params: {target_pose: [0.30, 0.00, 0.40, 0, 180, 0]}\n"
    path = _file(tmp_path, NO_PLACE + 20 * move)  # 44 steps once the body is written twice
    repairs = service.repair(path, BIN_PICKING)
    assert repairs and all(r.unrolls is None and len(r.task.loops) == 1 for r in repairs)
    [loop] = repairs[0].task.loops
    assert _commands(repairs[0].task, loop.entry, loop.first - 1).count("open-gripper") == 1
    assert service.check(repairs[0].task, BIN_PICKING).plausible


# ---- each edit of a loop body's two copies reaches the written step, and the copies' edits are united

def _with(repairs: list[Repair], *edits: tuple[str, int | None, str | None]) -> Repair:
    """The repair whose edits are exactly these (kind, step, device), in the order the repair lists them."""
    return next(r for r in repairs if [(e.kind, e.step, e.device) for e in r.edits] == list(edits))


def _written(r: Repair) -> tuple[list[str], list[tuple[int, int, int]]]:
    return [s.command for s in r.task.steps], [(lp.entry, lp.first, lp.last) for lp in r.task.loops]


THREE = ["localize-part", "pick", "place"]
TWO_GRIPPERS = """cell: two-grippers
devices:
""" + "".join(f"  - {DESCRIPTIONS / 'devices' / n}.ttl\n" for n in ("robot", "gripper", "magnetic-gripper",
                                                                      "sensor3d", "binpicking-pc"))


def test_a_role_rebound_in_both_iterations_is_rebound_in_the_written_step(tmp_path: Path) -> None:
    path = _file(tmp_path, UNTIL_EMPTY.replace("gripper: gripper}", "gripper: sensor3d}"))
    repairs = service.repair(path, BIN_PICKING, top=8)
    r = _with(repairs, ("rebind", 2, "gripper"), ("rebind", 5, "gripper"))
    assert r.unrolls is None and _written(r) == (THREE * 2, [(1, 4, 6)])
    assert (r.task.name, r.task.file, r.task.description) == (
        "bin-picking-until-empty", str(path), "Localise, pick and place parts until the bin-picking PC finds the bin "
        "empty.")
    assert r.task.steps[1].bind == r.task.steps[4].bind == {"robot": "robot", "gripper": "gripper"}
    assert service.check(r.task, BIN_PICKING).plausible
    # one iteration rebinds the pick, the other removes it and closes the gripper instead: removed from the body
    r = _with(repairs, ("rebind", 2, "gripper"), ("remove", 5, None), ("insert", 6, None))
    assert r.unrolls is None and _written(r) == (["localize-part", "close-gripper", "place"] * 2, [(1, 4, 6)])


def test_a_step_after_the_loop_is_removed_and_the_loop_stays_as_written(tmp_path: Path) -> None:
    path = _file(tmp_path, UNTIL_EMPTY + "  - command: open-gripper\n")  # the place left the gripper open
    repairs = service.repair(path, BIN_PICKING, top=4)
    r = _with(repairs, ("remove", 7, None))
    assert r.unrolls is None and _written(r) == (THREE * 2, [(1, 4, 6)])
    r = _with(repairs, ("insert", 7, None))
    assert r.unrolls is None and _written(r) == (THREE * 2 + ["close-gripper", "open-gripper"], [(1, 4, 6)])


def test_the_first_step_removed_before_a_loop_leaves_the_loop(tmp_path: Path) -> None:
    repairs = service.repair(_file(tmp_path, CLOSED_FIRST), BIN_PICKING, top=8)
    r = _with(repairs, ("remove", 1, None))
    assert r.unrolls is None and _written(r) == (THREE * 2, [(1, 4, 6)])
    # the first iteration swaps, the second opens before its pick: no written placement says that
    r = _with(repairs, ("swap", 3, None), ("insert", 6, None))
    assert r.unrolls is not None and r.task.loops == ()


def test_iterations_binding_a_role_to_different_devices_keep_their_flat_steps(tmp_path: Path) -> None:
    cell = _file(tmp_path, TWO_GRIPPERS).rename(tmp_path / "two-grippers.yaml")
    path = _file(tmp_path, UNTIL_EMPTY.replace("bind: {robot: robot, gripper: gripper}", "bind: {robot: robot}"))
    repairs = service.repair(path, cell, top=8)
    same = _with(repairs, *(("bind", i, "gripper") for i in (2, 3, 5, 6)))
    assert same.unrolls is None and _written(same) == (THREE * 2, [(1, 4, 6)])
    r = _with(repairs, ("bind", 2, "magnetic-gripper"), ("reset", 2, None), ("bind", 3, "magnetic-gripper"),
              ("bind", 5, "gripper"), ("bind", 6, "gripper"))
    assert r.unrolls == UNROLLS + "the iterations of the loop repair step 2 (pick) differently"
    assert r.task.loops == () and [s.bind.get("gripper") for s in r.task.steps] == [
        None, "magnetic-gripper", "magnetic-gripper", None, "gripper", "gripper"]


def test_a_rebinding_of_one_iteration_is_checked_for_every_iteration(tmp_path: Path) -> None:
    """The first iteration picks with the magnetic gripper and the second with the gripper: in the written loop the
    magnetic gripper would pick twice without letting go, which the check of the written task says."""
    cell = _file(tmp_path, TWO_GRIPPERS).rename(tmp_path / "two-grippers.yaml")
    repairs = service.repair(_file(tmp_path, NO_PLACE), cell, top=10)
    r = _with(repairs, ("rebind", 2, "magnetic-gripper"), ("reset", 2, None))
    assert (r.unrolls or "").startswith(UNROLLS + "kept in the loop or branch it is not plausible (loop iteration 2 "
                                        "and later: step 4 (pick): device 'magnetic-gripper' (role 'gripper')")


def test_a_step_one_iteration_removes_is_removed_from_the_loop_body(tmp_path: Path) -> None:
    path = _file(tmp_path, UNTIL_EMPTY.replace("exposure: 25", "exposure: 5000"))
    repairs = service.repair(path, BIN_PICKING, top=8)
    r = _with(repairs, ("reset", 1, None), ("reset", 4, None))
    assert r.unrolls is None and _written(r) == (THREE * 2, [(1, 4, 6)]) and "exposure" not in r.task.steps[0].params
    r = _with(repairs, ("reset", 1, None), ("remove", 4, None))  # the body would lose the step that ends the loop
    assert r.unrolls is not None and "no step of its body can end with that outcome" in r.unrolls


def test_the_edits_after_a_removed_step_reach_their_written_steps(tmp_path: Path) -> None:
    path = _file(tmp_path, UNTIL_EMPTY.replace("grip_force: 45", "grip_force: 5000").replace("speed: 80", "speed: 150"))
    repairs = service.repair(path, BIN_PICKING, top=10)
    r = _with(repairs, ("insert", 2, None), ("remove", 2, None), ("reset", 3, None), ("reset", 5, None),
              ("reset", 6, None))
    assert r.unrolls is None and _written(r) == (["localize-part", "close-gripper", "place"] * 2, [(1, 4, 6)])
    assert "speed" not in r.task.steps[2].params  # the place runs at its default speed


def test_swaps_in_both_iterations_are_made_in_the_loop_body(tmp_path: Path) -> None:
    path = _file(tmp_path, UNTIL_EMPTY + "  - command: open-gripper\n")
    r = _with(service.repair(path, BIN_PICKING, top=16), ("insert", 1, None), ("swap", 2, None), ("swap", 5, None))
    assert r.unrolls is None
    assert _written(r) == (["close-gripper", *["localize-part", "place", "pick"] * 2, "open-gripper"], [(2, 5, 7)])


BRANCH_STEPS = ["localize-part", "pick", "place", "move-to", "scan-bin"]


def test_a_step_removed_from_a_branch_leaves_the_branches_and_what_follows(tmp_path: Path) -> None:
    repairs = service.repair(_file(tmp_path, TWO_PICKS_IN_A_BRANCH), BIN_PICKING, top=6)
    r = _with(repairs, ("remove", 2, None))
    assert r.unrolls is None and [s.command for s in r.task.steps] == BRANCH_STEPS
    assert [(b.outcome.rsplit("#")[1], b.step, b.first, b.last) for b in r.task.branches] == [
        ("PartFound", 1, 2, 3), ("NoPartFound", 1, 4, 4)]
    r = _with(repairs, ("swap", 3, None))  # made in the branch, whose end then differs from the other branch's
    assert r.task.branches == () and [s.command for s in r.task.steps] == [
        "localize-part", "pick", "place", "pick", "move-to", "scan-bin"]
    assert (r.unrolls or "").startswith(UNROLLS + "kept in the loop or branch it is not plausible (branch NoPartFound "
                                        "at step 1: device gripper is left in state 'open', but branch PartFound")
    r = _with(repairs, ("swap", 1, None), ("insert", 2, None))  # the localize would go into its own branch
    assert r.unrolls == UNROLLS + "it swaps steps that are not neighbours in one list of the task file"
    assert r.task.branches == () and [s.command for s in r.task.steps][:3] == ["pick", "open-gripper", "localize-part"]


def test_a_repair_removing_the_step_branches_hang_on_keeps_its_flat_steps(tmp_path: Path) -> None:
    path = _file(tmp_path, TWO_PICKS_IN_A_BRANCH.replace("exposure: 25", "exposure: 5000"))
    r = _with(service.repair(path, BIN_PICKING, top=6), ("remove", 1, None), ("insert", 3, None))
    assert r.unrolls == UNROLLS + "it removes step 1, whose branches would lose their step"
    assert r.task.branches == () and [s.command for s in r.task.steps] == ["pick", "open-gripper", *BRANCH_STEPS[1:]]


def test_a_repair_of_a_task_with_a_loop_in_a_loop_keeps_its_flat_steps(tmp_path: Path) -> None:
    r = service.repair(_file(tmp_path, REGRIP), BIN_PICKING)[0]
    assert r.unrolls == UNROLLS + "the task has a loop inside a loop" and r.task.loops == ()


def test_a_loop_repaired_with_a_device_bought_from_the_catalogue_keeps_its_loop(tmp_path: Path) -> None:
    cell = tmp_path / "no-gripper.yaml"
    cell.write_text("cell: no-gripper\ndevices:\n" + "".join(
        f"  - {DESCRIPTIONS / 'devices' / n}.ttl\n" for n in ("robot", "sensor3d", "binpicking-pc")), encoding="utf-8")
    repairs = service.repair(_file(tmp_path, UNTIL_EMPTY), cell, DESCRIPTIONS / "devices", top=3)
    r = _with(repairs, ("add", None, "gripper"))
    assert r.added_devices == ("gripper",) and r.unrolls is None and _written(r) == (THREE * 2, [(1, 4, 6)])


def test_steps_inserted_in_two_places_go_to_their_written_places(tmp_path: Path) -> None:
    """The gripper is closed before the loop and nothing in the body lets go: each iteration needs it opened."""
    path = _file(tmp_path, CLOSED_FIRST[: CLOSED_FIRST.index("        - command: place")])
    repairs = service.repair(path, BIN_PICKING, top=10)
    r = _with(repairs, ("insert", 2, None), ("insert", 4, None))  # before each iteration's localize: one step
    assert r.unrolls is None
    assert _written(r) == (["close-gripper", *["open-gripper", "localize-part", "pick"] * 2], [(2, 5, 7)])
    r = next(r for r in repairs if [e.text for e in r.edits] == [
        "insert open-gripper before step 2 (localize-part)", "insert place before step 4 (localize-part)"])
    assert r.unrolls is None  # the open before the loop, the place at the end of its body
    assert _written(r) == (["close-gripper", "open-gripper", *["localize-part", "pick", "place"] * 2], [(3, 6, 8)])
    r = next(r for r in repairs if [e.text for e in r.edits] == [
        "insert place before step 3 (pick)", "insert open-gripper before step 5 (pick)"])
    assert r.unrolls == UNROLLS + "the loop's iterations repair it differently"  # place or open before the pick


def test_a_step_inserted_before_a_branching_step_moves_its_branches(tmp_path: Path) -> None:
    text = TWO_PICKS_IN_A_BRANCH.replace("steps:\n  - name: localize", "steps:\n  - command: close-gripper\n  - name: localize")
    repairs = service.repair(_file(tmp_path, text), BIN_PICKING, top=6)
    r = next(r for r in repairs if [e.text for e in r.edits] == [
        "insert open-gripper before step 2 (localize-part)", "insert open-gripper before step 4 (pick)"])
    assert r.unrolls is None and [s.command for s in r.task.steps] == [
        "close-gripper", "open-gripper", "localize-part", "pick", "open-gripper", "pick", "place", "move-to", "scan-bin"]
    assert [(b.outcome.rsplit("#")[1], b.step, b.first, b.last) for b in r.task.branches] == [
        ("PartFound", 3, 4, 7), ("NoPartFound", 3, 8, 8)]
    assert service.check(r.task, BIN_PICKING).plausible


def test_a_task_without_loops_or_branches_keeps_its_repeat(tmp_path: Path) -> None:
    path = _file(tmp_path, "task: squeeze\nrepeat: 2\nsteps:\n  - command: close-gripper\n    params: {grip_force: 5000}\n"
                           "  - command: open-gripper\n")
    r = _with(service.repair(path, BIN_PICKING), ("reset", 1, None), ("reset", 3, None))
    assert r.unrolls is None and r.task.repeat == 2 and r.task.steps[0].params == {}


# ---- the side effects of a repair kept in the loop are those of its written steps

def _effects(a: AssessedRepair) -> list[tuple[str, int | None, str]]:
    return [(e.kind, e.step, e.text) for e in a.side_effects]


def test_the_side_effects_of_a_repair_kept_in_the_loop_are_those_of_the_steps_it_changes(tmp_path: Path) -> None:
    """Rebinding the pick's gripper in the loop body changes no step's values, as in the same task without the loop:
    no side effect. A close-gripper written into the body instead of the pick is a new step in every iteration,
    and runs with its default grip force in each."""
    path = _file(tmp_path, UNTIL_EMPTY.replace("gripper: gripper}", "gripper: sensor3d}"))
    assessed = service.assessed_repairs(path, BIN_PICKING, top=8)
    rebound = next(a for a in assessed if [(e.kind, e.step) for e in a.repair.edits] == [("rebind", 2), ("rebind", 5)])
    assert rebound.repair.unrolls is None and rebound.repair.task.loops and _effects(rebound) == []
    closed = next(a for a in assessed if [(e.kind, e.step) for e in a.repair.edits] == [
        ("rebind", 2), ("remove", 5), ("insert", 6)])
    assert closed.repair.unrolls is None and _written(closed.repair) == (
        ["localize-part", "close-gripper", "place"] * 2, [(1, 4, 6)])
    assert _effects(closed) == [
        ("default_values", 2, "step 2 (close-gripper) runs with default values: grip_force = 40"),
        ("default_values", 5, "step 5 (close-gripper) runs with default values: grip_force = 40")]
    assert rebound.rank < closed.rank


def test_a_repair_kept_in_the_loop_moves_no_device_the_step_after_the_loop_relies_on(tmp_path: Path) -> None:
    """A library step after the loop holds the robot where the loop's last place left it. Rebinding the pick's
    gripper in the body leaves every step where it was, so no step moves the robot anew: each repair's side effects
    are those of its written steps only, and the rebinding, with none, comes first."""
    path = _file(tmp_path, UNTIL_EMPTY.replace("gripper: gripper}", "gripper: sensor3d}") + "  - command: hold\n")
    knowledge = service.knowledge((Path(__file__).parents[1] / "data" / "libraries" / "holding",))
    assessed = service.assessed_repairs(path, BIN_PICKING, top=3, knowledge=knowledge)
    defaults = [("default_values", n, f"step {n} (close-gripper) runs with default values: grip_force = 40")
                for n in (2, 5)]
    assert [([(e.kind, e.step) for e in a.repair.edits], _effects(a)) for a in assessed] == [
        ([("rebind", 2), ("rebind", 5)], []),
        ([("rebind", 2), ("remove", 5), ("insert", 6)], defaults),
        ([("remove", 2), ("insert", 3), ("rebind", 5)], defaults)]
    assert all(a.repair.unrolls is None and _written(a.repair)[1] == [(1, 4, 6)] for a in assessed)


def test_a_repair_of_a_loop_in_a_loop_that_keeps_every_step_is_written_out_step_by_step(tmp_path: Path) -> None:
    """Resetting the exposure keeps every flat step where it was; the note says the loops are written out, and
    the resulting task is: its steps one by one, with no loop left to run them again."""
    text = (TASKS / "bin-picking-in-rounds.yaml").read_text(encoding="utf-8").replace("exposure: 25", "exposure: 5000")
    r = _with(service.repair(_file(tmp_path, text), BIN_PICKING, top=1), *(("reset", n, None) for n in (1, 4, 8, 11)))
    assert r.unrolls == UNROLLS + "the task has a loop inside a loop"
    assert r.task.loops == () and r.task.branches == ()
    assert [s.command for s in r.task.steps] == (THREE * 2 + ["move-to"]) * 2
    assert all("exposure" not in s.params for s in r.task.steps)
