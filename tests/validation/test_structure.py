"""Structure rules of process charts that neither the schema nor the shapes express."""

from __future__ import annotations

import pytest

from plugnproduce.validation import validate_paths
from tests.conftest import edit


@pytest.mark.parametrize(
    ("old", "new", "needle"),
    [
        ('pnp:params="grip_force"', 'pnp:params="grip_strength"', "consumes parameter 'grip_strength', which process"),
        ('pnp:params="grip_force"', 'pnp:params="speed"', "parameter 'speed' is for role 'robot', but region 'gripper'"),
        ("In('robot_at_part')", "In('gripper_open')", "waits for In('gripper_open'), which is not a state of another"),
        ('id="robot_lift" pnp:concept="Moving"', 'id="robot_lift" pnp:concept="GripForce"',
         "annotated with GripForce, which is not a state concept"),
    ],
)
def test_process_chart_structure(process_copy, old: str, new: str, needle: str) -> None:
    ttl, scxml = process_copy("pick")
    edit(scxml, old, new)
    problems = validate_paths([ttl.parent]).problems
    hits = [p for p in problems if needle in p.message]
    assert len(hits) == 1, [str(p) for p in problems]
    assert hits[0].file == str(scxml) and hits[0].line > 0


def test_region_must_end_in_final(process_copy) -> None:
    ttl, scxml = process_copy("open-gripper")
    edit(scxml, '<final id="gripper_open"', '<state id="gripper_open"')
    problems = validate_paths([ttl]).problems
    assert any("must end in a <final> state" in p.message and p.file == str(scxml) for p in problems)
