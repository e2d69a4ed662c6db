"""A loop inside a loop: read into one loop record per copy of the outer body, written back as nested."""

from __future__ import annotations

import pytest

from plugnproduce.description.loader import parse_task
from plugnproduce.description.taskfile import task_to_yaml
from plugnproduce.errors import DescriptionError

NESTED = b"""task: rounds
steps:
  - loop:
      max: 3
      steps:
        - command: scan-bin
        - loop:
            until: BinEmpty
            max: 4
            steps:
              - command: localize-part
              - command: pick
        - command: move-to
  - command: place
"""


def test_an_inner_loop_appears_once_in_each_copy_of_the_outer_body() -> None:
    task = parse_task(NESTED, "rounds.yaml")
    assert [s.command for s in task.steps] == (["scan-bin"] + ["localize-part", "pick"] * 2 + ["move-to"]) * 2 + [
        "place"]
    assert [(lp.entry, lp.first, lp.last, lp.max) for lp in task.loops] == [(1, 7, 12, 3), (2, 4, 5, 4),
                                                                           (8, 10, 11, 4)]
    assert [lp.line for lp in task.loops] == [4, 8, 8]  # the line of each loop's first key


def test_a_step_of_an_inner_loop_names_both_iterations_outermost_first() -> None:
    task = parse_task(NESTED, "rounds.yaml")
    assert task.path(2) == "loop iteration 1, loop iteration 1"
    assert task.path(5) == "loop iteration 1, loop iteration 2 and later"
    assert task.path(10) == "loop iteration 2 and later, loop iteration 2 and later"
    assert task.path(12) == "loop iteration 2 and later"
    assert task.path(13) is None


def test_the_loops_around_a_step_are_found_outermost_first() -> None:
    task = parse_task(NESTED, "rounds.yaml")
    assert [lp.entry for lp in task.loops_at(9)] == [1, 8]
    assert task.loop_at(9) == task.loops[0]


def test_the_writer_writes_the_inner_loop_inside_the_outer_one() -> None:
    task = parse_task(NESTED, "rounds.yaml")
    again = parse_task(task_to_yaml(task).encode(), "rounds.yaml")
    assert again.steps == task.steps
    assert [(lp.entry, lp.first, lp.last, lp.until, lp.max) for lp in again.loops] == [
        (lp.entry, lp.first, lp.last, lp.until, lp.max) for lp in task.loops]


def test_loops_nest_three_deep() -> None:
    text = b"""task: deep
steps:
  - loop:
      max: 2
      steps:
        - loop:
            max: 2
            steps:
              - loop: {max: 2, steps: [{command: pick}]}
"""
    task = parse_task(text, "deep.yaml")
    assert len(task.steps) == 8 and len(task.loops) == 1 + 2 + 4
    assert task.path(8) == "loop iteration 2 and later, loop iteration 2 and later, loop iteration 2 and later"


def test_loops_nested_beyond_the_step_limit_are_refused_at_the_loop_that_passes_it() -> None:
    text = "task: deep\nsteps:\n"
    for depth in range(14):  # each level doubles the steps: 2**14 > 10000
        text += "  " * (2 * depth + 1) + "- loop:\n" + "  " * (2 * depth + 3) + "max: 2\n" + "  " * (2 * depth + 3) \
            + "steps:\n"
    text += "  " * 29 + "- command: pick\n"
    with pytest.raises(DescriptionError, match="the task makes more than 10000 steps") as err:
        parse_task(text.encode(), "deep.yaml")
    assert err.value.line == 4  # the outermost loop (its first key): its second copy of the body would pass the limit


INNER_FIRST = b"""task: inner-first
steps:
  - loop:
      max: 2
      steps:
        - loop:
            until: BinEmpty
            max: 3
            steps:
              - command: localize-part
              - command: pick
        - command: place
"""


def test_a_loop_starting_where_its_outer_loop_starts_comes_after_it() -> None:
    task = parse_task(INNER_FIRST, "inner-first.yaml")
    assert [(lp.entry, lp.first, lp.last) for lp in task.loops] == [(1, 6, 10), (1, 3, 4), (6, 8, 9)]
    assert [(lp.entry, lp.last) for lp in task.loops_at(1)] == [(1, 10), (1, 4)]  # its first step: both loops
    assert [(lp.entry, lp.last) for lp in task.loops_at(4)] == [(1, 10), (1, 4)]  # the inner loop's last step
    assert [(lp.entry, lp.last) for lp in task.loops_at(5)] == [(1, 10)]
    assert [(lp.entry, lp.last) for lp in task.loops_at(10)] == [(1, 10)]  # the outer loop's last step
    assert task.loops_at(11) == ()
    loop = task.loop_at(1)
    assert loop is not None and (loop.entry, loop.last) == (1, 10)
    assert task.path(1) == "loop iteration 1, loop iteration 1"
