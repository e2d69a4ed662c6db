"""The journal's value records: which step's device produced a value, and which later request carried it.

A device event outside any step (before the first, after the last) produces no value record."""

from __future__ import annotations

import pytest

from plugnproduce import service
from plugnproduce.chartnames import output_variable
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.loader import parse_task
from plugnproduce.executor import values
from tests.codegen.conftest import bind_by_skill

LOCALIZE = """task: look-until-empty
steps:
  - loop:
      until: BinEmpty
      max: 3
      steps:
        - command: move-to
          params: {target_pose: [0.4, 0, 0.3, 0, 180, 0], speed: 50}
        - name: localize
          command: localize-part
          bind: {sensor: sensor3d, localizer: binpicking-pc}
          params: {exposure: 25, part_type: bracket}
"""
"""The loop's body is written twice in the task chart (steps 1-2 its first round, 3-4 the later ones): the last
step, 4, is the localisation whose outcome ends the loop."""
POSE = [0.5, 0.1, 0.02, 0.0, 180.0, 0.0]


@pytest.fixture(scope="module")
def look_until_empty() -> GeneratedTask:
    k = service.knowledge()
    processes = {p.id: p for p in k.processes}
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    task = parse_task(LOCALIZE.encode(), "task.yaml")
    return generate_task(task, cell, bind_by_skill(task, cell, processes), processes, k.taxonomy)


def test_the_last_steps_device_produces_the_outcome_that_ends_the_loop(look_until_empty: GeneratedTask) -> None:
    assert len(look_until_empty.steps) == 4
    found = values.produced(look_until_empty, 4, "binpicking-pc", {"part_pose": POSE, "outcome": "BinEmpty"})
    assert found == [{"value": "outcome", "produced": "BinEmpty", "step": 4, "device": "binpicking-pc"}]


@pytest.mark.parametrize("step", [None, 0, 5])
def test_an_event_outside_every_step_produces_nothing(look_until_empty: GeneratedTask, step: int | None) -> None:
    assert values.produced(look_until_empty, step, "binpicking-pc", {"part_pose": POSE, "outcome": "PartFound"}) == []


@pytest.mark.parametrize("step", [None, 0, 5])
def test_a_request_outside_every_step_carries_nothing(look_until_empty: GeneratedTask, step: int | None) -> None:
    assert values.used(look_until_empty, step, "binpicking-pc", {"exposure": 25}, {}) == []


def test_another_device_of_the_step_produces_nothing(look_until_empty: GeneratedTask) -> None:
    assert values.produced(look_until_empty, 4, "sensor3d", {"part_pose": POSE, "outcome": "PartFound"}) == []


LINKED = """task: localize-then-pick
steps:
  - name: localize
    command: localize-part
    bind: {sensor: sensor3d, localizer: binpicking-pc}
    params: {exposure: 25, part_type: bracket}
  - command: pick
    bind: {robot: robot, gripper: gripper}
    params:
      pick_pose: {from: localize, output: part_pose}
      grip_force: 45
"""


@pytest.fixture(scope="module")
def localize_then_pick() -> GeneratedTask:
    k = service.knowledge()
    processes = {p.id: p for p in k.processes}
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    task = parse_task(LINKED.encode(), "task.yaml")
    return generate_task(task, cell, bind_by_skill(task, cell, processes), processes, k.taxonomy)


PRODUCED = {output_variable("localize", "part_pose"): POSE}
"""The task chart's datamodel once the localisation reported its pose."""


def test_the_last_step_carries_the_value_an_earlier_step_produced(localize_then_pick: GeneratedTask) -> None:
    assert values.used(localize_then_pick, 2, "robot", {"TargetPose": POSE}, PRODUCED) == [
        {"value": "localize.part_pose", "used": POSE, "step": 2, "device": "robot", "parameter": "pick_pose"}]


def test_the_first_step_produces_the_output_a_later_step_takes_under_its_name(
        localize_then_pick: GeneratedTask) -> None:
    found = values.produced(localize_then_pick, 1, "binpicking-pc",
                            {"part_pose": POSE, "part_type": "bracket", "outcome": "PartFound"})
    assert found == [{"value": "localize.part_pose", "produced": POSE, "step": 1, "device": "binpicking-pc"}]


def test_a_request_to_another_device_of_the_step_carries_no_earlier_output(localize_then_pick: GeneratedTask) -> None:
    # the gripper of the pick is sent no pose, even one equal to the one the robot takes
    assert values.used(localize_then_pick, 2, "gripper", {"TargetPose": POSE}, PRODUCED) == []


def test_a_value_other_than_the_one_produced_is_not_journalled_as_used(localize_then_pick: GeneratedTask) -> None:
    elsewhere = [0.4, 0.1, 0.02, 0.0, 180.0, 0.0]
    assert values.used(localize_then_pick, 2, "robot", {"TargetPose": elsewhere}, PRODUCED) == []
