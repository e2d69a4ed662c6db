"""The check of branches on an outcome: every path, each refusal at its line and naming its path."""

from __future__ import annotations

import shutil
from pathlib import Path

from plugnproduce import service
from plugnproduce.description.loader import load_device
from tests.conftest import edit
from tests.reasoning.test_flow_check import CELL, TASKS, UNTIL_EMPTY, checked, line_of

THEN_HOME = (TASKS / "bin-picking-then-home.yaml").read_text(encoding="utf-8")

GRIPPER_CLOSED = """task: closed
steps:
  - name: localize
    command: localize-part
    on:
      NoPartFound:
        - command: close-gripper
  - command: pick
    params:
      pick_pose: {from: localize, output: part_pose}
  - command: place
"""


def test_the_shipped_branching_task_is_plausible() -> None:
    result = service.check(TASKS / "bin-picking-then-home.yaml", CELL)
    assert result.plausible, [str(p) for p in result.problems]


def test_a_branch_that_leaves_the_gripper_closed_before_a_pick_is_refused_after_it(tmp_path: Path) -> None:
    result, path = checked(tmp_path, GRIPPER_CLOSED)
    [problem] = [p for p in result.problems if p.kind == "wrong_state"]
    assert problem.where.line == line_of(path, "command: pick") and problem.step == 3
    assert problem.text.startswith("after branch NoPartFound at step 1: step 3 (pick): device 'gripper'")
    assert "left there by step 2 (close-gripper)" in problem.text and not result.plausible


def test_a_branch_must_leave_the_devices_as_going_on_without_it_does(tmp_path: Path) -> None:
    result, path = checked(tmp_path, GRIPPER_CLOSED)
    [problem] = [p for p in result.problems if p.kind == "branch_join"]
    assert problem.where.line == line_of(path, "NoPartFound:") and problem.device == "gripper"
    assert problem.text.startswith("branch NoPartFound at step 1: device gripper is left in state 'closed', but "
                                   "going on without a branch leaves it in 'open'")


def test_the_path_without_the_branch_is_checked_too(tmp_path: Path) -> None:
    # a pick inside the branch taken when a part is found; the place after it must also work without it
    text = """task: without
steps:
  - name: localize
    command: localize-part
    on:
      PartFound:
        - command: pick
          params: {pick_pose: {from: localize, output: part_pose}}
  - command: place
"""
    result, path = checked(tmp_path, text)
    wrong = [p for p in result.problems if p.kind == "wrong_state"]
    assert [(p.step, p.where.line) for p in wrong] == [(3, line_of(path, "command: place"))]
    assert "step 3 (place): device 'gripper'" in wrong[0].text and not wrong[0].text.startswith("after")


def test_each_branch_of_a_step_starts_from_the_states_the_step_left(tmp_path: Path) -> None:
    # the NoPartFound branch is written after the pick and place of PartFound, but starts where localize left
    result, _ = checked(tmp_path, THEN_HOME)
    move_to = next(s for s in result.steps if s.command == "move-to")
    localize = result.steps[0]
    assert move_to.states["gripper"] == localize.states["gripper"] == "open"
    assert move_to.states["robot"] == "home"


def test_a_link_to_an_output_made_only_in_a_branch_is_refused_at_the_value(tmp_path: Path) -> None:
    text = """task: only-in-a-branch
steps:
  - command: localize-part
    on:
      PartFound:
        - name: again
          command: localize-part
  - command: pick
    params:
      pick_pose: {from: again, output: part_pose}
  - command: place
"""
    result, path = checked(tmp_path, text)
    [problem] = [p for p in result.problems if p.kind == "bad_link"]
    assert problem.where.line == line_of(path, "pick_pose:") and problem.parameter == "pick_pose"
    assert problem.text == ("step 3 (pick): parameter pick_pose takes part_pose from again, but step 2 (again) "
                            "runs only on branch PartFound at step 1; a step may take only an output produced on "
                            "every path to it")


def test_a_link_inside_the_branch_to_its_own_step_is_fine(tmp_path: Path) -> None:
    text = THEN_HOME.replace("            PartFound:\n              - command: pick",
                             "            PartFound:\n              - name: again\n                command: "
                             "localize-part\n              - command: pick").replace("from: localize", "from: again")
    result, _ = checked(tmp_path, text)
    assert not [p for p in result.problems if p.kind == "bad_link"], [str(p) for p in result.problems]


def test_a_problem_in_a_branch_in_a_loop_names_both(tmp_path: Path) -> None:
    text = THEN_HOME.replace("              - command: move-to\n",
                             "              - command: close-gripper\n              - command: move-to\n")
    result, path = checked(tmp_path, text)
    joins = sorted({p.text.split(":")[0] for p in result.problems if p.kind == "branch_join"})
    assert joins == ["branch NoPartFound at step 1", "branch NoPartFound at step 6"]
    later = [p for p in result.problems if p.kind == "wrong_state" and p.command == "pick"]
    assert [p.text.split(": step")[0] for p in later] == [
        "loop iteration 2 and later, branch PartFound at step 6, after branch NoPartFound at step 1"]
    assert all(p.where.line == line_of(path, "command: pick") for p in later)


def test_an_unreachable_branch_is_refused_by_the_check_too(tmp_path: Path) -> None:
    text = GRIPPER_CLOSED.replace("NoPartFound:", "NoPartFund:")
    result, path = checked(tmp_path, text)
    [problem] = [p for p in result.problems if p.kind == "bad_flow"]
    assert problem.where.line == line_of(path, "NoPartFund:")
    assert "did you mean NoPartFound or PartFound?" in problem.text


def test_a_step_in_a_branch_is_explained_from_the_states_it_starts_from(tmp_path: Path) -> None:
    # move-to (step 4) starts where localize left the robot, not where place (step 3, the other branch) did
    explanation = service.explain_step(TASKS / "bin-picking-then-home.yaml", CELL, 4)
    [robot] = [r.text for r in explanation.states if "device 'robot'" in r.text]
    assert "step 3" not in robot and "its initial state" in robot and explanation.plausible


def test_a_task_with_more_paths_than_are_checked_is_refused_not_checked_for_ever(tmp_path: Path) -> None:
    text = "task: many\nsteps:\n" + "  - command: localize-part\n    on:\n      PartFound: [{command: scan-bin}]\n" * 150
    result, _ = checked(tmp_path, text)
    assert [p.kind for p in result.problems] == ["too_many_paths"] and not result.plausible
    assert "at most 100 paths" in result.problems[0].text


def test_an_unreachable_branch_is_one_bad_flow_finding_at_its_line(tmp_path: Path) -> None:
    result, path = checked(tmp_path, GRIPPER_CLOSED.replace("NoPartFound:", "NoPartFund:"))
    [problem] = [p for p in result.problems if p.kind == "bad_flow"]
    where = f"{path}:{line_of(path, 'NoPartFund:')}"
    shown = problem.to_json()
    assert (shown["step"], shown["command"], shown["where"], shown["rests_on"], shown["iris"]) == (
        1, "localize-part", where, [where], [])
    assert problem.reason.code == "bad_flow" and not result.plausible
    assert (result.task, result.cell) == ("closed", "bin-picking")


def test_a_loop_of_a_branched_task_is_refused_where_each_of_its_ends_strands_the_gripper(tmp_path: Path) -> None:
    text = (UNTIL_EMPTY.replace("steps:\n  - loop:", "steps:\n  - command: localize-part\n    on:\n"
                                "      PartFound: [{command: scan-bin}]\n  - loop:", 1)
            + "  - command: open-gripper\n    bind: {gripper: gripper}\n")
    result, path = checked(tmp_path, text)
    exits = [p for p in result.problems if "loop ended on BinEmpty" in p.text]
    assert {p.text.split(":")[0] for p in exits} == {"loop ended on BinEmpty at step 3 (loop iteration 1)",
                                                    "loop ended on BinEmpty at step 6 (loop iteration 2 and later)"}
    assert {(p.step, p.kind, p.device, p.where.line) for p in exits} == {
        (9, "wrong_state", "gripper", line_of(path, "- command: open-gripper"))}
    assert not result.plausible


def test_a_link_in_a_branch_to_an_output_the_device_never_reports_is_refused_naming_the_branch(
        tmp_path: Path) -> None:
    for f in ("binpicking-pc.ttl", "binpicking-pc.scxml"):
        shutil.copy(service.builtin("devices", f), tmp_path)
    edit(tmp_path / "binpicking-pc.scxml", '<param name="part_pose" expr="part_pose" pnp:maxReach="1.2"/>', "")
    cell = service.cell(CELL).with_device(load_device(tmp_path / "binpicking-pc.ttl", service.knowledge().taxonomy))
    path = tmp_path / "task.yaml"
    path.write_text("task: silent\nsteps:\n  - name: localize\n    command: localize-part\n    on:\n"
                    "      PartFound:\n        - command: pick\n"
                    "          params: {pick_pose: {from: localize, output: part_pose}}\n"
                    "        - command: place\n", encoding="utf-8")
    result = service.check(path, cell)
    [problem] = [p for p in result.problems if p.kind == "bad_link"]
    assert (problem.step, problem.device, problem.parameter) == (2, "binpicking-pc", "pick_pose")
    assert problem.where.line == line_of(path, "pick_pose:") and not result.plausible
    assert problem.text == ("branch PartFound at step 1: step 2 (pick): parameter pick_pose takes part_pose from "
                            "localize, but device 'binpicking-pc' (role 'localizer') reports no part_pose: no event "
                            "of its chart carries a value of that name")


def test_a_step_after_an_until_loop_in_a_task_with_branches_is_checked_from_where_each_exit_leaves(
        tmp_path: Path) -> None:
    # as in a task without branches (test_flow_check): the loop can end at step 1 or at step 4
    text = UNTIL_EMPTY + ("  - command: localize-part\n    on:\n      NoPartFound: [{command: scan-bin}]\n"
                          "  - command: open-gripper\n    bind: {gripper: gripper}\n")
    result, path = checked(tmp_path, text)
    exits = sorted((p.step, p.text.split(": step")[0], p.where.line) for p in result.problems
                   if "loop ended on" in p.text)
    line = line_of(path, "- command: open-gripper")
    assert exits == [(9, "loop ended on BinEmpty at step 1 (loop iteration 1)", line),
                     (9, "loop ended on BinEmpty at step 4 (loop iteration 2 and later)", line)]
    assert not result.plausible


def test_the_branches_of_a_step_after_an_until_loop_are_not_run_one_after_the_other(tmp_path: Path) -> None:
    # each branch closes the open gripper: run one after the other, the second would find it closed
    text = UNTIL_EMPTY + ("  - command: localize-part\n    on:\n"
                          "      PartFound: [{command: close-gripper}]\n      NoPartFound: [{command: close-gripper}]\n")
    result, _ = checked(tmp_path, text)
    assert result.plausible and not result.problems, [str(p) for p in result.problems]


def test_the_findings_of_a_step_after_an_until_loop_are_listed_by_parameter_on_every_exit(tmp_path: Path) -> None:
    # the values out of range are found on the path that ends the loop after a whole iteration and on each exit
    text = UNTIL_EMPTY + ("  - command: localize-part\n    on:\n      NoPartFound: [{command: scan-bin}]\n"
                          "  - command: pick-and-place\n    params: {speed: 500, grip_force: 500}\n")
    result, _ = checked(tmp_path, text)
    assert [(p.step, p.kind, p.parameter) for p in result.problems] == [
        (9, "too_high", "grip_force")] * 3 + [(9, "too_high", "speed")] * 3
    said = "step 9 (pick-and-place): parameter grip_force = 500 N is above its maximum 140 N"
    assert [p.text for p in result.problems][:3] == [
        said, f"loop ended on BinEmpty at step 1 (loop iteration 1): {said}",
        f"loop ended on BinEmpty at step 4 (loop iteration 2 and later): {said}"]


def test_a_branch_after_an_until_loop_is_checked_from_where_each_exit_leaves(tmp_path: Path) -> None:
    # the loop may end at localize-part with the gripper closed; then a part found after the loop closes it again
    text = """task: close-while-looking
steps:
  - loop:
      until: BinEmpty
      max: 10
      steps:
        - command: close-gripper
        - command: localize-part
        - command: open-gripper
  - command: localize-part
    on:
      PartFound: [{command: close-gripper}, {command: open-gripper}]
"""
    result, path = checked(tmp_path, text)
    assert not result.plausible
    assert sorted((p.step, p.text.split(": step")[0], p.where.line) for p in result.problems) == [
        (8, "loop ended on BinEmpty at step 2 (loop iteration 1), branch PartFound at step 7", 12),
        (8, "loop ended on BinEmpty at step 5 (loop iteration 2 and later), branch PartFound at step 7", 12)]
    assert all("device 'gripper' (role 'gripper') is in state 'closed'" in p.text for p in result.problems)
