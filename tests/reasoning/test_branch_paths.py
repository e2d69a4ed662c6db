"""The paths through a task's branches, as a user sees them: which steps each path checks, how a finding on a
path is numbered and named, how the ways on from a step are compared, and where the number of paths stops."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from plugnproduce import reasoning, service
from plugnproduce.description.loader import load_device
from plugnproduce.errors import UnknownName
from plugnproduce.reasoning.checks import branches, plausibility
from tests.conftest import edit
from tests.reasoning.test_branch_check import GRIPPER_CLOSED
from tests.reasoning.test_flow_check import CELL, checked, line_of

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "part-finding"
"""A library whose find-part reports three outcomes: PartFound, BinEmpty and its own PartOccluded."""


def _findings(result: service.reasoning.CheckResult) -> list[tuple[int, str, str | None]]:
    return [(p.step, p.kind, p.device) for p in result.problems]


def test_going_on_past_two_branches_not_taken_checks_the_step_after_them(tmp_path: Path) -> None:
    # PartOccluded takes neither branch: the place after them starts with the gripper as find-part left it
    path = tmp_path / "task.yaml"
    path.write_text("""task: two-branches-and-on
steps:
  - name: found
    command: find-part
    on:
      PartFound:
        - command: pick
          params: {pick_pose: {from: found, output: part_pose}}
      BinEmpty:
        - command: close-gripper
  - command: place
""", encoding="utf-8")
    result = service.check(path, CELL, service.knowledge((LIBRARY,)))
    assert _findings(result) == [(2, "branch_join", "gripper"), (2, "branch_join", "robot"),
                                 (3, "branch_join", "gripper"), (4, "wrong_state", "gripper")]
    place = result.problems[-1]
    assert place.where.line == line_of(path, "command: place")
    assert place.text.startswith("step 4 (place): device 'gripper' (role 'gripper') is in state 'open'")
    assert result.final_states["robot"] == "at_pose"  # the place ran on the path without a branch


TWO_WAYS = """task: two-ways
steps:
  - command: localize-part
    on:
      PartFound:
        - command: close-gripper
      NoPartFound:
        - command: move-to
          params: {target_pose: [0.30, 0.00, 0.40, 0, 180, 0]}
"""


def test_two_branches_that_leave_the_devices_unlike_are_compared_with_each_other(tmp_path: Path) -> None:
    # every outcome of localize-part takes a branch: NoPartFound's branch is compared with PartFound's
    result, path = checked(tmp_path, TWO_WAYS)
    gripper = next(p for p in result.problems if p.device == "gripper")
    where = f"{path}:{line_of(path, 'NoPartFound:')}"
    text = ("branch NoPartFound at step 1: device gripper is left in state 'open', but branch PartFound at step 1 "
            "leaves it in 'closed'; every way on from step 1 must leave each device in one state, as the steps "
            "after it start from it")
    assert gripper.to_json() == {
        "step": 3, "command": "move-to", "kind": "branch_join", "text": text, "plain": text, "where": where,
        "role": None, "device": "gripper", "state": "open", "state_concept": None, "needed": None,
        "parameter": None, "iris": [], "rests_on": [where]}
    assert _findings(result) == [(3, "branch_join", "gripper"), (3, "branch_join", "robot")]


def test_an_outcome_that_ends_the_loop_never_reaches_the_steps_after_the_branches(tmp_path: Path) -> None:
    # BinEmpty (a NoPartFound) ends the loop, so every way on from localize takes the PartFound branch
    result, _ = checked(tmp_path, """task: until-none
steps:
  - loop:
      until: NoPartFound
      max: 5
      steps:
        - name: localize
          command: localize-part
          on:
            PartFound:
              - command: pick
                params: {pick_pose: {from: localize, output: part_pose}}
              - command: place
                params: {place_pose: [0.60, -0.20, 0.10, 0, 180, 0]}
""")
    assert result.plausible, [str(p) for p in result.problems]


def test_branches_on_an_unknown_command_are_one_finding_not_a_crash(tmp_path: Path) -> None:
    result, path = checked(tmp_path, "task: unknown\nsteps:\n  - command: localise-part\n    on:\n"
                                     "      PartFound:\n        - command: scan-bin\n")
    assert [str(p) for p in result.problems] == [
        f"{path}:3: step 1: unknown process command 'localise-part'; did you mean localize-part or machine-part?"]


def test_a_step_whose_branches_no_outcome_takes_does_not_stop_the_join_of_the_next(tmp_path: Path) -> None:
    result, path = checked(tmp_path, """task: unreachable-first
steps:
  - command: scan-bin
    on:
      PartFound:
        - command: scan-bin
  - name: localize
    command: localize-part
    on:
      NoPartFound:
        - command: close-gripper
""")
    assert _findings(result) == [(1, "bad_flow", None), (4, "branch_join", "gripper")]
    assert result.problems[1].where.line == line_of(path, "NoPartFound:")


def test_a_branch_inside_a_branch_is_compared_on_the_path_that_reaches_it(tmp_path: Path) -> None:
    # localize again (step 4) runs only in the PartFound branch, after the robot placed the part: going on
    # without its NoPartFound branch leaves the robot where place left it, as the branch does
    result, path = checked(tmp_path, """task: nested
steps:
  - name: localize
    command: localize-part
    on:
      PartFound:
        - command: pick
          params: {pick_pose: {from: localize, output: part_pose}}
        - command: place
          params: {place_pose: [0.60, -0.20, 0.10, 0, 180, 0]}
        - command: localize-part
          on:
            NoPartFound:
              - command: close-gripper
""")
    joins = [(p.text.split(":")[0], p.device) for p in result.problems if p.kind == "branch_join"]
    assert joins == [("branch PartFound at step 1", "gripper"), ("branch PartFound at step 1", "robot"),
                     ("branch NoPartFound at step 4", "gripper")]
    assert result.problems[-1].where.line == line_of(path, "NoPartFound:")


MANY = """task: many-findings
steps:
  - command: place
    params: {place_pose: [0.60, -0.20, 0.10, 0, 180, 0]}
  - name: localize
    command: localize-part
    on:
      NoPartFound:
        - command: place
          params: {place_pose: [0.60, -0.20, 0.10, 0, 180, 0]}
  - command: pick
    params: {pick_pose: {from: nowhere, output: part_pose}}
  - command: pick
    params: {pick_pose: {from: localize, output: part_pose}}
"""


def test_every_finding_of_every_path_is_kept_numbered_and_named_as_the_task_is(tmp_path: Path) -> None:
    # the path without the branch runs steps 1, 2, 4 and 5: its findings carry the task's numbers, and a
    # finding in the branch names the branch once
    result, path = checked(tmp_path, MANY)
    assert [s.index for s in result.steps] == [1, 2, 3, 4, 5]
    assert [(p.step, p.kind, p.where.line) for p in result.problems] == [
        (1, "wrong_state", 3), (3, "wrong_state", 9), (4, "bad_link", 12), (5, "wrong_state", 13)]
    texts = [p.text for p in result.problems]
    assert texts[0].startswith("step 1 (place): device 'gripper' (role 'gripper') is in state 'open'")
    assert texts[1].startswith("branch NoPartFound at step 2: step 3 (place): device 'gripper'")
    assert "left there by step 1 (place)" in texts[1]
    assert texts[3].startswith("step 5 (pick): device 'gripper' (role 'gripper') is in state 'closed'")
    assert "left there by step 4 (pick)" in texts[3]


def test_a_value_no_command_of_the_device_accepts_is_refused_at_each_step_of_every_path(tmp_path: Path) -> None:
    # a gripper whose Close takes no grip force: the force given to the close-gripper after the branch is lost
    for f in ("gripper.ttl", "gripper.scxml"):
        shutil.copy(service.builtin("devices", f), tmp_path)
    edit(tmp_path / "gripper.scxml", ' pnp:accepts="GripForce"', "")
    edit(tmp_path / "gripper.ttl", "pnp:hasArgument dev:gripper-Close-GripForce , ", "pnp:hasArgument ")
    cell = service.cell(CELL).with_device(load_device(tmp_path / "gripper.ttl", service.knowledge().taxonomy))
    path = tmp_path / "task.yaml"
    path.write_text("""task: lost-force
steps:
  - command: localize-part
    on:
      NoPartFound:
        - command: scan-bin
  - command: close-gripper
    params: {grip_force: 45}
""", encoding="utf-8")
    result = service.check(path, cell)
    assert [str(p) for p in result.problems] == [
        f"{path}:8: step 3 (close-gripper): parameter grip_force (grip force) goes to device 'gripper' (role "
        "'gripper'), but no command of its chart accepts grip force; the value would be lost"]


LIMITED = """task: three-paths
steps:
  - command: localize-part
    on:
      PartFound: [{command: scan-bin}]
  - command: localize-part
    on:
      PartFound: [{command: scan-bin}]
"""
"""Three paths: without a branch (2 steps), through the first branch (3 steps), through the second (3 steps)."""


def _limits(monkeypatch: pytest.MonkeyPatch, paths: int, steps: int) -> None:
    for module in (branches, plausibility):
        monkeypatch.setattr(module, "MAX_PATHS", paths)
        monkeypatch.setattr(module, "MAX_PATH_STEPS", steps)


@pytest.mark.parametrize(("paths", "steps", "refused"), [
    (3, 8, False),  # exactly at both limits
    (2, 8, True),  # one path over
    (3, 7, True),  # one step over
    (3, 5, True),  # the first two paths hold exactly 5 steps: the third is one path too many
])
def test_the_paths_checked_stop_exactly_at_their_limits(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                        paths: int, steps: int, refused: bool) -> None:
    _limits(monkeypatch, paths, steps)
    result, _ = checked(tmp_path, LIMITED)
    kinds = [p.kind for p in result.problems]
    assert kinds == ["too_many_paths"] if refused else "too_many_paths" not in kinds, kinds


@pytest.mark.parametrize(("paths", "steps"), [(1, 10_000), (100, 4)])
def test_a_task_over_the_limits_is_refused_at_the_branch_where_they_were_passed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, paths: int, steps: int) -> None:
    _limits(monkeypatch, paths, steps)
    result, path = checked(tmp_path, LIMITED)
    [problem] = result.problems
    assert (problem.step, problem.command, problem.kind) == (1, "localize-part", "too_many_paths")
    assert str(problem.where) == f"{path}:{line_of(path, 'PartFound:')}" and problem.reason.where == (problem.where,)
    assert f"at most {paths} paths of {steps} steps in all" in problem.text
    assert (result.task, result.cell, result.plausible, result.steps) == ("three-paths", "bin-picking", False, ())


@pytest.mark.parametrize("n", [0, 5])
def test_a_step_the_branched_task_does_not_have_is_not_explained(tmp_path: Path, n: int) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(LIMITED, encoding="utf-8")
    with pytest.raises(UnknownName) as refused:
        service.explain_step(path, CELL, n)
    assert str(refused.value) == f"unknown step {n}; the task has steps 1 to 4"


def test_the_first_step_of_a_branched_task_is_explained_as_the_first(tmp_path: Path) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(LIMITED, encoding="utf-8")
    ex = service.explain_step(path, CELL, 1)
    assert (ex.step, ex.command, ex.plausible) == (1, "localize-part", True)


def test_why_a_step_is_not_plausible_is_answered_on_the_path_that_makes_it_so(tmp_path: Path) -> None:
    # the pick (step 3) is plausible going on without the branch, not after the branch closed the gripper
    path = tmp_path / "task.yaml"
    path.write_text(GRIPPER_CLOSED, encoding="utf-8")
    k = service.knowledge()
    ontology = reasoning.ontology_of(k.ontology_files(), k.taxonomy)
    ex = reasoning.explain_plausible(service.as_task(path), 3, service.cell(CELL), k, ontology)
    assert ex.answer is False
    sentences = [s for _, s in ex.derivation.sentences()]
    assert "step 2 (close-gripper) left device 'gripper' in state 'closed'" in sentences, sentences


@pytest.mark.parametrize(("text", "n", "plausible", "said"), [
    # the first step closes the gripper: the open-gripper of the second branch starts from it
    ("  - command: close-gripper\n", 5, True, "left there by step 1 (close-gripper)"),
    # the close-gripper of the second branch starts from the gripper's initial state
    ("", 4, True, "its initial state"),
])
def test_a_step_no_checked_path_runs_is_explained_on_the_task_as_written(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, text: str, n: int, plausible: bool, said: str) -> None:
    _limits(monkeypatch, 1, 10_000)  # only the path without a branch and the first branch's path
    second = "close-gripper" if not text else "open-gripper"
    task = (f"task: past-the-limit\nsteps:\n{text}"
            "  - command: localize-part\n    on:\n      PartFound: [{command: scan-bin}]\n"
            f"  - command: localize-part\n    on:\n      PartFound: [{{command: {second}}}]\n")
    path = tmp_path / "task.yaml"
    path.write_text(task, encoding="utf-8")
    ex = service.explain_step(path, CELL, n)
    assert (ex.step, ex.command, ex.plausible) == (n, second, plausible)
    [gripper] = [r.text for r in ex.states if "device 'gripper'" in r.text]
    assert said in gripper, gripper


def test_a_task_over_the_limit_of_paths_is_refused_at_the_last_branch_it_reached(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _limits(monkeypatch, 2, 10_000)  # the second branch makes the third path, one too many
    result, path = checked(tmp_path, LIMITED)
    [problem] = [p.to_json() for p in result.problems]
    second = f"{path}:{line_of(path, 'PartFound:') + 3}"
    assert (problem["step"], problem["command"], problem["kind"]) == (1, "localize-part", "too_many_paths")
    assert (problem["where"], problem["rests_on"], problem["iris"]) == (second, [second], [])
    assert result.problems[0].reason.code == "too_many_paths"


def test_a_step_of_the_second_branch_is_explained_with_its_own_number(tmp_path: Path) -> None:
    # step 3 is the second step of the path that runs it: its number, its states and its problem say step 3
    path = tmp_path / "task.yaml"
    path.write_text("task: either\nsteps:\n  - command: localize-part\n    on:\n"
                    "      PartFound: [{command: close-gripper}]\n      NoPartFound: [{command: open-gripper}]\n",
                    encoding="utf-8")
    ex = service.explain_step(path, CELL, 3)
    assert (ex.step, ex.command, ex.plausible) == (3, "open-gripper", False)
    assert [str(p) for p in ex.problems] == [
        f"{path}:6: step 3 (open-gripper): device 'gripper' (role 'gripper') is in state 'open' [open (pnp:Open)] "
        "(its initial state); the step needs it closed (pnp:Closed)"]
    assert [p.step for p in ex.problems] == [3]


def test_a_step_after_a_branch_is_explained_with_the_numbers_of_the_task(tmp_path: Path) -> None:
    # place (step 4) is the third step of the path without the branch: the step that left the gripper is step 3
    path = tmp_path / "task.yaml"
    path.write_text(GRIPPER_CLOSED, encoding="utf-8")
    ex = service.explain_step(path, CELL, 4)
    assert (ex.step, ex.command, ex.plausible, ex.problems) == (4, "place", True, ())
    [gripper] = [r.text for r in ex.states if "device 'gripper'" in r.text]
    assert "left there by step 3 (pick)" in gripper, gripper


def test_a_task_whose_one_path_is_over_the_limit_of_steps_is_refused_at_its_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # the branch is on an outcome localize-part does not have: the only path is the one without it, 3 steps long
    _limits(monkeypatch, 100, 2)
    result, path = checked(tmp_path, "task: one-path\nsteps:\n  - command: localize-part\n    on:\n"
                                     "      NoPartFund: [{command: scan-bin}]\n  - command: scan-bin\n"
                                     "  - command: scan-bin\n")
    [problem] = [p.to_json() for p in result.problems]
    assert (problem["step"], problem["command"], problem["kind"]) == (1, "localize-part", "too_many_paths")
    assert (problem["where"], problem["rests_on"]) == (str(path), [str(path)]) and not result.plausible
