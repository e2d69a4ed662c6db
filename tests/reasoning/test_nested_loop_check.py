"""The check of a loop inside a loop: each copy of the inner loop is checked, problems name both iterations."""

from __future__ import annotations

from pathlib import Path

from plugnproduce import service
from tests.reasoning.test_flow_check import CELL, TASKS, checked, line_of

ROUNDS = (TASKS / "bin-picking-in-rounds.yaml").read_text(encoding="utf-8")

REGRIP = """task: regrip
steps:
  - loop:
      max: 2
      steps:
        - name: localize
          command: localize-part
          bind: {sensor: sensor3d, localizer: binpicking-pc}
          params: {exposure: 25, part_type: bracket}
        - command: pick
          bind: {robot: robot, gripper: gripper}
          params: {pick_pose: {from: localize, output: part_pose}, grip_force: 45}
        - loop:
            max: 2
            steps:
              - command: open-gripper
                bind: {gripper: gripper}
              - command: close-gripper
                bind: {gripper: gripper}
"""


def test_the_shipped_nested_task_is_plausible() -> None:
    result = service.check(TASKS / "bin-picking-in-rounds.yaml", CELL)
    assert result.plausible, [str(p) for p in result.problems]


def test_an_inner_loop_leaving_the_gripper_closed_for_the_next_outer_iteration_is_refused(tmp_path: Path) -> None:
    result, path = checked(tmp_path, REGRIP)
    assert not result.plausible
    [problem] = result.problems
    assert problem.where.line == line_of(path, "- command: pick")
    assert problem.text.startswith("loop iteration 2 and later: step 8 (pick): device 'gripper'")
    assert "is in state 'closed'" in problem.text and "needs it open" in problem.text


def test_the_inner_loop_regripping_without_opening_again_is_refused_on_its_own_path(tmp_path: Path) -> None:
    result, _ = checked(tmp_path, REGRIP.replace("""              - command: open-gripper
                bind: {gripper: gripper}
""", ""))
    texts = [p.text for p in result.problems if p.device == "gripper"]
    assert any(t.startswith("loop iteration 1, loop iteration 2 and later: ") for t in texts), texts


def test_steps_after_an_inner_loop_are_checked_where_its_until_ends_it(tmp_path: Path) -> None:
    text = ROUNDS.replace("        - command: move-to\n", "        - command: open-gripper\n"
                          "          bind: {gripper: gripper}\n        - command: move-to\n")
    result, path = checked(tmp_path, text)
    exits = {p.text.split(":")[0] for p in result.problems if "loop ended on BinEmpty" in p.text}
    assert exits == {"loop ended on BinEmpty at step 1 (loop iteration 1, loop iteration 1)",
                     "loop ended on BinEmpty at step 4 (loop iteration 1, loop iteration 2 and later)",
                     "loop ended on BinEmpty at step 9 (loop iteration 2 and later, loop iteration 1)",
                     "loop ended on BinEmpty at step 12 (loop iteration 2 and later, loop iteration 2 and later)"}
    assert not result.plausible


def test_an_outer_until_every_inner_loop_ends_on_first_is_refused_at_the_outer_loop(tmp_path: Path) -> None:
    text = ROUNDS.replace("      max: 3\n      steps:\n        - loop:", "      until: BinEmpty\n      max: 3\n"
                          "      steps:\n        - loop:", 1)
    result, path = checked(tmp_path, text)
    [problem] = [p for p in result.problems if p.kind == "bad_flow"]
    assert problem.where.line == line_of(path, "until: BinEmpty")
    assert "lies in an inner loop that ends on it first, so the loop never ends on it" in problem.text


def test_an_unknown_outcome_of_an_inner_loop_is_refused_once(tmp_path: Path) -> None:
    result, _ = checked(tmp_path, ROUNDS.replace("until: BinEmpty", "until: BinEmty"))
    assert [p.text for p in result.problems if p.kind == "bad_flow"] == [
        "loop iteration 1, loop iteration 1: loop until BinEmty: BinEmty is not an outcome of the ontology; "
        "did you mean BinEmpty?"]


def test_a_repair_of_a_nested_task_keeps_its_flat_steps_and_says_why(tmp_path: Path) -> None:
    _, path = checked(tmp_path, REGRIP)
    r = next(r for r in service.repair(path, CELL) if [e.text for e in r.edits] == [
        "insert open-gripper before step 8 (pick)"])
    assert r.unrolls == ("this repair writes the task's loops and branches out step by step: "
                         "the task has a loop inside a loop")
    assert r.task.loops == () and len(r.task.steps) == 12 + 1  # the flat steps and the one inserted
