"""Device descriptions, charts, tasks and cells, mutated from the built-in examples and generated.

Each case is either read or refused with a ``DescriptionError`` (or a finding in the
validation report) whose message is one line, names no traceback and quotes at most a
short excerpt; anything else fails with the case Hypothesis shrank it to.
"""

from __future__ import annotations

import random

import yaml
from fuzzing import Workspace, mutate, run_cell, run_chart, run_task, run_turtle, seeds
from hypothesis import given, settings
from hypothesis import strategies as st

FUZZ = settings.get_profile("fuzz")
DEEP = st.sampled_from([False, False, False, True])  # one case in four is also validated in full (slower)


@FUZZ
@given(seed=st.sampled_from(seeds("turtle")), rng=st.randoms(use_true_random=False), deep=DEEP)
def test_mutated_turtle_is_read_or_refused_in_one_line(workspace: Workspace, seed: tuple[str, bytes],
                                                       rng: random.Random, deep: bool) -> None:
    relative, data = seed
    assert run_turtle(workspace, relative, mutate(data, rng), deep) in ("accepted", "refused")


@FUZZ
@given(seed=st.sampled_from(seeds("chart")), rng=st.randoms(use_true_random=False), deep=DEEP)
def test_mutated_chart_is_read_or_refused_in_one_line(workspace: Workspace, seed: tuple[str, bytes],
                                                      rng: random.Random, deep: bool) -> None:
    relative, data = seed
    assert run_chart(workspace, relative, mutate(data, rng), deep) in ("accepted", "refused")


@FUZZ
@given(seed=st.sampled_from(seeds("task")), rng=st.randoms(use_true_random=False))
def test_mutated_task_is_read_or_refused_in_one_line(workspace: Workspace, seed: tuple[str, bytes],
                                                     rng: random.Random) -> None:
    relative, data = seed
    assert run_task(workspace, relative, mutate(data, rng), deep=False) in ("accepted", "refused")


@FUZZ
@given(seed=st.sampled_from(seeds("cell")), rng=st.randoms(use_true_random=False), deep=DEEP)
def test_mutated_cell_is_read_or_refused_in_one_line(workspace: Workspace, seed: tuple[str, bytes],
                                                     rng: random.Random, deep: bool) -> None:
    relative, data = seed
    assert run_cell(workspace, relative, mutate(data, rng), deep) in ("accepted", "refused")


SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-(10**60), max_value=10**60),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=30),
)
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8),
                                                                                           inner, max_size=4),
                      max_leaves=12)
STEPS = st.lists(st.fixed_dictionaries(
    {"command": st.sampled_from(["pick", "place", "bin-pick", "move-to", "nope"]) | SCALARS},
    optional={"bind": st.dictionaries(st.text(max_size=10), st.text(max_size=10) | SCALARS, max_size=3),
              "params": st.dictionaries(st.sampled_from(["speed", "grip_force", "place_pose", "x"]), VALUES,
                                        max_size=3)}), max_size=4)
TASKS = st.fixed_dictionaries({"task": st.text(max_size=20) | SCALARS, "steps": STEPS | VALUES},
                              optional={"repeat": st.integers(min_value=-5, max_value=10**6) | SCALARS,
                                        "description": SCALARS, "extra": VALUES})


@FUZZ
@given(task=TASKS)
def test_generated_task_is_read_or_refused_in_one_line(workspace: Workspace, task: dict[str, object]) -> None:
    data = yaml.safe_dump(task, allow_unicode=True).encode()
    assert run_task(workspace, "tasks/bin-picking.yaml", data, deep=False) in ("accepted", "refused")


@FUZZ
@given(devices=st.lists(st.sampled_from(["../devices/gripper.ttl", "../devices/robot.ttl", "/etc/passwd", "/dev/zero",
                                         ".", "../devices", "x" * 300, "a/" * 600, "../devices/gripper.scxml"])
                        | st.text(max_size=40), max_size=4),
       name=SCALARS)
def test_generated_cell_is_read_or_refused_in_one_line(workspace: Workspace, devices: object, name: object) -> None:
    data = yaml.safe_dump({"cell": name, "devices": devices}, allow_unicode=True).encode()
    assert run_cell(workspace, "cells/assembly.yaml", data, deep=False) in ("accepted", "refused")
