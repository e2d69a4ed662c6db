"""``Step.at``: a step renumbered for its place in another task (the windowed repair renumbers every step of a long
task after its first insertion) keeps everything but its position."""

from __future__ import annotations

import dataclasses

from plugnproduce.description.model import Step
from plugnproduce.description.tasks import Link


def _full() -> Step:
    return Step(7, "place", {"robot": "r1"}, {"speed": 40, "pose": Link("scan", "pose", (0.0, 0.0, 0.1))}, 12,
                {"speed": 14, "pose": 15}, "put")


def test_a_step_moved_keeps_every_field_but_its_index() -> None:
    step = _full()
    moved = step.at(9)
    assert moved.index == 9 and moved == dataclasses.replace(step, index=9)
    assert {f.name: getattr(moved, f.name) for f in dataclasses.fields(Step) if f.name != "index"} == \
        {f.name: getattr(step, f.name) for f in dataclasses.fields(Step) if f.name != "index"}


def test_a_step_already_in_place_is_itself() -> None:
    step = _full()
    assert step.at(7) is step
