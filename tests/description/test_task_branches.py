"""Branches on an outcome in task files: how they are read (flattened, numbered, named), written back and refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.description.flow import Branch
from plugnproduce.description.loader import load_task, parse_task, task_to_yaml
from plugnproduce.description.model import Task
from plugnproduce.errors import DescriptionError

P = "http://plugnproduce.org/ontology#"

NESTED = b"""task: nested
steps:
  - loop:
      until: BinEmpty
      max: 5
      steps:
        - name: localize
          command: localize-part
          on:
            NoPartFound:
              - command: scan-bin
                on:
                  PartFound:
                    - command: open-gripper
            PartFound:
              - command: pick
                params: {pick_pose: {from: localize, output: part_pose}}
              - command: place
  - command: scan-bin
    on: {BinEmpty: [{command: open-gripper}]}
"""


def _shape(task: Task) -> list[tuple[int, str, str | None]]:
    return [(s.index, s.command, task.path(s.index)) for s in task.steps]


def test_branches_follow_their_step_and_a_loop_holds_them_twice() -> None:
    task = parse_task(NESTED, "nested.yaml")
    assert _shape(task)[:5] == [
        (1, "localize-part", "loop iteration 1"),
        (2, "scan-bin", "loop iteration 1, branch NoPartFound at step 1"),
        (3, "open-gripper", "loop iteration 1, branch NoPartFound at step 1, branch PartFound at step 2"),
        (4, "pick", "loop iteration 1, branch PartFound at step 1"),
        (5, "place", "loop iteration 1, branch PartFound at step 1"),
    ]
    assert _shape(task)[5:7] == [(6, "localize-part", "loop iteration 2 and later"),
                                 (7, "scan-bin", "loop iteration 2 and later, branch NoPartFound at step 6")]
    assert _shape(task)[10:] == [(11, "scan-bin", None), (12, "open-gripper", "branch BinEmpty at step 11")]
    assert [(b.step, b.outcome, b.first, b.last, b.line) for b in task.branches_of(6)] == [
        (6, P + "NoPartFound", 7, 8, 10), (6, P + "PartFound", 9, 10, 15)]


@pytest.mark.parametrize("block", [False, True])
def test_the_writer_writes_branches_as_the_file_nests_them(block: bool) -> None:
    task = parse_task(NESTED, "nested.yaml")
    again = parse_task(task_to_yaml(task, block=block).encode(), "again.yaml")
    assert _shape(again) == _shape(task)
    assert [(b.step, b.outcome, b.first, b.last) for b in again.branches] == \
        [(b.step, b.outcome, b.first, b.last) for b in task.branches]
    assert [s.params for s in again.steps] == [s.params for s in task.steps]


def test_a_loop_may_go_on_while_an_outcome_comes() -> None:
    task = parse_task(b"task: t\nsteps:\n  - loop:\n      while: PartFound\n      steps:\n"
                      b"        - command: localize-part\n", "t.yaml")
    assert task.loops[0].while_outcome == P + "PartFound" and task.loops[0].until is None
    assert "while: PartFound" in task_to_yaml(task)


@pytest.mark.parametrize(
    ("text", "line", "needle"),
    [
        ("task: t\nsteps:\n  - command: pick\n    on: [place]\n", 4, "on maps outcomes to the steps"),
        ("task: t\nsteps:\n  - command: pick\n    on:\n      NoPartFound: []\n", 5,
         "branch NoPartFound needs its steps, a non-empty list"),
        ("task: t\nsteps:\n  - command: pick\n    on:\n      No part: [{command: place}]\n", 5,
         "on names outcomes such as NoPartFound"),
        ("task: t\nsteps:\n  - command: pick\n    on:\n      NoPartFound: [{command: place}]\n"
         "      NoPartFound: [{command: place}]\n", 6, "key 'NoPartFound' appears twice"),
        ("task: t\nrepeat: 2\nsteps:\n  - command: pick\n    on: {NoPartFound: [{command: place}]}\n", 5,
         "a task with a branch cannot also repeat"),
        ("task: t\nsteps:\n  - loop:\n      max: 2\n      steps:\n        - command: pick\n          on:\n"
         "            NoPartFound:\n              - loop: {max: 2, steps: []}\n", 9,
         "a loop needs 'steps', a non-empty list"),
        ("task: t\nsteps:\n  - command: pick\n    on:\n      NoPartFound:\n        - name: a\n          command: x\n"
         "  - name: a\n    command: place\n", 8, "step name 'a' appears twice"),
    ],
)
def test_bad_branches_name_file_and_line(tmp_path: Path, text: str, line: int, needle: str) -> None:
    f = tmp_path / "t.yaml"
    f.write_text(text)
    with pytest.raises(DescriptionError) as err:
        load_task(f)
    assert (err.value.file, err.value.line) == (str(f), line)
    assert needle in err.value.message


def test_a_loop_inside_a_branch_runs_once_and_is_written_back() -> None:
    text = (b"task: t\nsteps:\n  - command: localize-part\n    on:\n      PartFound:\n"
            b"        - loop: {max: 3, steps: [{command: pick}, {command: place}]}\n  - command: scan-bin\n")
    task = parse_task(text, "t.yaml")
    assert [s.command for s in task.steps] == ["localize-part", "pick", "place", "pick", "place", "scan-bin"]
    assert (task.branches[0].first, task.branches[0].last) == (2, 5)
    assert (task.loops[0].entry, task.loops[0].first, task.loops[0].last) == (2, 4, 5)
    assert _shape(parse_task(task_to_yaml(task).encode(), "t.yaml")) == _shape(task)


@pytest.mark.parametrize("outcome", ["https://example.org/cell/outcomes#NoPartFound",
                                     "https://example.org/cell/outcomes/NoPartFound", "NoPartFound"])
def test_a_branch_is_named_by_its_outcomes_local_name_however_the_iri_ends(outcome: str) -> None:
    assert Branch(3, outcome, 4, 5).path == "branch NoPartFound at step 3"
