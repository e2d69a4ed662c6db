"""The check of a task's data links, as a user reads it: each link that cannot get its value is one finding at the
line of the value, saying what is wrong, once however often the step runs."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.reasoning.test_flow_check import checked, line_of

LOCALIZE = "  - name: localize\n    command: localize-part\n"


def _links(tmp_path: Path, text: str) -> list[tuple[int, int, str]]:
    result, path = checked(tmp_path, text)
    assert not result.plausible
    return [(p.step, p.where.line, p.text) for p in result.problems if p.kind == "bad_link"]


def test_a_link_to_a_name_no_step_has_lists_that_no_step_is_named(tmp_path: Path) -> None:
    text = "task: unnamed\nsteps:\n  - command: localize-part\n  - command: pick\n" \
           "    params:\n      pick_pose: {from: localize, output: part_pose}\n"
    assert _links(tmp_path, text) == [(2, 6, "step 2 (pick): parameter pick_pose takes part_pose from localize, but "
                                             "no step is named 'localize'; named steps: none")]


def test_a_step_taking_its_own_output_is_refused_as_coming_after_it(tmp_path: Path) -> None:
    text = "task: own\nsteps:\n  - name: again\n    command: localize-part\n" \
           "  - name: pick\n    command: pick\n    params:\n      pick_pose: {from: pick, output: part_pose}\n"
    assert _links(tmp_path, text) == [(2, 8, "step 2 (pick): parameter pick_pose takes part_pose from pick, but "
                                             "step 2 (pick) comes after it; a value must be produced first")]


@pytest.mark.parametrize("repeat", ["", "repeat: 3\n"])
def test_a_wrong_link_in_the_last_step_is_one_finding_however_often_the_task_runs(tmp_path: Path,
                                                                                   repeat: str) -> None:
    text = f"task: last\n{repeat}steps:\n{LOCALIZE}  - command: pick\n" \
           "    params:\n      pick_pose: {from: localize, output: part_type}\n"
    [(step, line, said)] = _links(tmp_path, text)
    assert (step, line) == (2, line_of(tmp_path / "task.yaml", "pick_pose:"))
    assert said == ("step 2 (pick): parameter pick_pose takes part_type from localize, a string; the parameter "
                    "takes a Pose")


def test_an_offset_on_an_output_that_is_no_pose_is_refused_at_the_value(tmp_path: Path) -> None:
    text = f"task: offset\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_type, offset: [0, 0, 0.1, 0, 0, 0]}\n"
    assert _links(tmp_path, text) == [(2, 7, "step 2 (pick): parameter pick_pose takes part_type from localize "
                                             "with an offset, but part_type is a string; only a pose takes an "
                                             "offset [x, y, z, rx, ry, rz]")]


def test_a_wrong_link_in_a_loop_is_one_finding_not_one_per_iteration(tmp_path: Path) -> None:
    text = ("task: looped\nsteps:\n  - loop:\n      until: BinEmpty\n      max: 5\n      steps:\n"
            "        - name: localize\n          command: localize-part\n        - command: pick\n"
            "          params:\n            pick_pose: {from: localize, output: pose}\n        - command: place\n")
    [(step, line, said)] = _links(tmp_path, text)
    assert (step, line) == (2, 11) and said.endswith("localize-part gives back no 'pose'; its outputs: part_pose, "
                                                     "part_type")
