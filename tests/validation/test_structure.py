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


def test_an_outcome_the_ontology_does_not_know_is_a_finding_at_its_state(process_copy) -> None:
    ttl, scxml = process_copy("localize-part")
    edit(scxml, 'pnp:outcomes="PartFound BinEmpty"', 'pnp:outcomes="PartFound BinEmty"')
    problems = validate_paths([ttl]).problems
    [hit] = [p for p in problems if "names outcome BinEmty" in p.message]
    assert hit.file == str(scxml) and hit.line == 21 and "did you mean BinEmpty?" in hit.message


def test_a_loop_until_an_outcome_its_steps_cannot_end_with_is_a_finding_at_the_loop(tmp_path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text("task: t\nsteps:\n  - loop:\n      until: PartFound\n      max: 3\n      steps:\n"
                    "        - command: pick\n", encoding="utf-8")
    problems = validate_paths([task]).problems
    [hit] = [p for p in problems if "loop until PartFound" in p.message]
    assert hit.file == str(task) and hit.line == 4
    assert "no step of its body can end with that outcome" in hit.message
