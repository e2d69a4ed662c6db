"""The plausibility check: the paper's implausible task, the valid ones, and its agreement with code generation."""

from __future__ import annotations

from dataclasses import replace

from plugnproduce import service
from plugnproduce.codegen import generate_task
from plugnproduce.description.model import Cell, Step
from tests.reasoning.conftest import task

OPEN, CLOSED = "http://plugnproduce.org/ontology#Open", "http://plugnproduce.org/ontology#Closed"


def test_the_bin_picking_task_is_plausible(cell: Cell) -> None:
    result = service.check(task("bin-picking"), cell)
    assert result.plausible and result.problems == ()


def test_the_answer_names_the_task_the_cell_and_each_step_by_its_number(cell: Cell) -> None:
    result = service.check(task("bin-picking-invalid"), cell)
    assert (result.task, result.cell) == ("bin-picking-invalid", "bin-picking")
    assert [s.index for s in result.steps] == list(range(1, len(task("bin-picking-invalid").steps) + 1))


def test_a_step_is_explained_under_its_own_number(cell: Cell) -> None:
    ex = service.explain_step(task("bin-picking-invalid"), cell, 2)
    assert (ex.step, ex.plausible) == (2, False) and [p.step for p in ex.problems] == [2]


def test_the_pick_and_place_task_is_plausible(cell: Cell) -> None:
    assert service.check(task("pick-and-place"), cell).plausible


def test_the_invalid_task_names_step_device_state_and_need(cell: Cell) -> None:
    result = service.check(task("bin-picking-invalid"), cell)
    assert not result.plausible
    (p,) = result.problems
    assert (p.step, p.kind, p.device, p.state, p.state_concept, p.needed) == (2, "wrong_state", "gripper", "closed",
                                                                               CLOSED, OPEN)
    assert p.where.file.endswith("bin-picking-invalid.yaml") and p.where.line == 8
    assert "left there by step 1" in p.text


def test_omitted_bindings_are_resolved_when_one_device_fits(cell: Cell) -> None:
    result = service.check(task("bin-picking"), cell)
    assert result.steps[1].bindings == {"gripper": "gripper", "robot": "robot"}


def test_two_fitting_devices_make_an_omitted_binding_ambiguous(cell: Cell, device) -> None:
    result = service.check(task("bin-picking"), cell.with_device(device("vacuum-gripper")))
    kinds = {(p.step, p.kind, p.role) for p in result.problems}
    assert (2, "ambiguous", "gripper") in kinds
    assert "gripper, vacuum-gripper" in next(p.text for p in result.problems if p.kind == "ambiguous")


def test_parameter_values_must_fit_type_and_range(cell: Cell) -> None:
    t = task("bin-picking-invalid")
    bad = replace(t, steps=(replace(t.steps[0], params={"grip_force": 200, "exposure": "long", "colour": 1}),))
    kinds = {(p.kind, p.parameter) for p in service.check(bad, cell).problems}
    assert kinds == {("too_high", "grip_force"), ("bad_type", "exposure"), ("unknown_param", "colour")}


def test_a_value_in_the_process_range_beyond_the_device_limit_is_a_finding_at_its_line(cell: Cell) -> None:
    t = task("bin-picking-invalid")
    bad = replace(t, steps=(replace(t.steps[0], params={"grip_force": 130}),))  # the process allows up to 140 N
    (p,) = [p for p in service.check(bad, cell).problems if p.parameter == "grip_force"]
    assert (p.kind, p.device, p.where) == ("device_limit", "gripper", t.where(t.steps[0], "grip_force"))
    assert "takes at most 100 N; the value is 130 N" in p.text
    assert p.reason.where[0].file.endswith("gripper.ttl")


def test_a_pose_is_six_numbers(cell: Cell) -> None:
    t = task("pick-and-place")
    short = replace(t, steps=(replace(t.steps[0], params={"pick_pose": [1, 2, 3]}),))
    (p,) = service.check(short, cell).problems
    assert (p.kind, p.parameter) == ("bad_type", "pick_pose")


def test_an_unknown_command_is_a_problem_not_an_error(cell: Cell) -> None:
    t = task("pick-and-place")
    odd = replace(t, steps=(Step(1, "fly", line=3),))
    (p,) = service.check(odd, cell).problems
    assert p.kind == "unknown_command"


def test_the_parameters_of_an_unknown_command_are_not_called_unknown_too(cell: Cell) -> None:
    # rules/params.lp: a parameter is unknown only to a process; a command that is none is one problem, once
    t = task("pick-and-place")
    odd = replace(t, steps=(Step(1, "fly", params={"speed": 10, "height": 2}, line=3),))
    (p,) = service.check(odd, cell).problems
    assert (p.kind, p.step) == ("unknown_command", 1)


def test_check_and_code_generation_agree_on_where_devices_are_left(cell: Cell) -> None:
    k = service.knowledge()
    t = task("bin-picking")
    result = service.check(t, cell)
    generated = generate_task(t, cell, result.bindings(), {p.id: p for p in k.processes}, k.taxonomy)
    assert result.final_states == generated.final_states


def test_explain_step_gives_every_device_its_state_and_need(cell: Cell) -> None:
    ex = service.explain_step(task("bin-picking-invalid"), cell, 2)
    assert not ex.plausible
    gripper = next(r for r in ex.states if "'gripper'" in r.text)
    assert "'closed'" in gripper.text and "open (pnp:Open)" in gripper.text and "not satisfied" in gripper.text
    assert gripper.where[0].file.endswith("gripper.scxml")


def test_explain_step_of_a_plausible_step(cell: Cell) -> None:
    ex = service.explain_step(task("bin-picking"), cell, 3)
    assert ex.plausible and len(ex.states) == 4


def test_each_wrong_binding_the_task_names_is_one_problem_of_its_kind(cell: Cell) -> None:
    t = task("pick-and-place")
    for bind, kind, role, device in (({"gripper": "cobot"}, "absent", "gripper", "cobot"),
                                     ({"gripper": "robot"}, "cannot_play", "gripper", "robot"),
                                     ({"hand": "gripper"}, "unknown_role", "hand", None)):
        bad = replace(t, steps=(replace(t.steps[0], bind=bind), t.steps[1]))
        (p,) = service.check(bad, cell).problems
        assert (p.step, p.kind, p.role, p.device) == (1, kind, role, device)
        assert f"role '{role}'" in p.text


def test_a_role_no_device_of_the_cell_can_play_says_why_each_candidate_cannot(cell: Cell, device) -> None:
    t = task("pick-and-place")
    (p,) = service.check(t, cell.without("gripper")).problems
    assert (p.step, p.kind, p.role) == (1, "no_device", "gripper")
    (p,) = service.check(t, cell.without("gripper").with_device(device("vacuum-gripper"))).problems
    assert (p.step, p.kind, p.role) == (1, "no_device", "gripper")
    assert "its request SuctionOn needs the argument vacuum (pnp:Vacuum)" in p.text


def test_a_value_below_the_process_minimum(cell: Cell) -> None:
    t = task("pick-and-place")
    bad = replace(t, steps=(replace(t.steps[0], params={**t.steps[0].params, "grip_force": 5}), t.steps[1]))
    (p,) = service.check(bad, cell).problems
    assert (p.step, p.kind, p.parameter) == (1, "too_low", "grip_force")
    assert "grip_force = 5 N is below its minimum 10 N" in p.text


def test_a_device_bound_to_a_role_it_lacks_an_argument_for_says_which_argument(cell: Cell, device) -> None:
    t = task("pick-and-place")
    bound = replace(t, steps=(replace(t.steps[0], bind={"gripper": "vacuum-gripper"}), t.steps[1]))
    (p,) = service.check(bound, cell.without("gripper").with_device(device("vacuum-gripper"))).problems
    assert (p.step, p.kind, p.role, p.device) == (1, "cannot_play", "gripper", "vacuum-gripper")
    assert "is bound to device 'vacuum-gripper', which cannot play it; device 'vacuum-gripper' cannot play role " \
           "'gripper' of pick-and-place: its request SuctionOn needs the argument vacuum (pnp:Vacuum)" in p.text
    assert any(str(w.file).endswith("vacuum-gripper.scxml") for w in p.reason.where)


def test_the_problems_of_one_step_are_listed_role_by_role_whatever_the_devices_are_called(cell: Cell) -> None:
    t = task("pick-and-place")
    bad = replace(t, steps=(replace(t.steps[0], bind={"robot": "a-robot", "gripper": "z-gripper"}), t.steps[1]))
    problems = service.check(bad, cell).problems
    assert [(p.step, p.kind, p.role, p.device) for p in problems] == [
        (1, "absent", "gripper", "z-gripper"), (1, "absent", "robot", "a-robot")]


def test_the_values_of_one_step_out_of_range_are_listed_by_parameter_name(cell: Cell) -> None:
    t = task("pick-and-place")
    params = {"speed": 500, **t.steps[0].params, "grip_force": 500}  # written speed first
    problems = service.check(replace(t, steps=(replace(t.steps[0], params=params), t.steps[1])), cell).problems
    assert [(p.step, p.kind, p.parameter) for p in problems] == [(1, "too_high", "grip_force"),
                                                                 (1, "too_high", "speed")]


def test_the_values_of_one_step_in_units_that_do_not_fit_are_listed_by_parameter_name(cell: Cell) -> None:
    t = task("pick-and-place")
    params = {"speed": "50 kg", **t.steps[0].params, "grip_force": "30 m"}  # written speed first
    problems = service.check(replace(t, steps=(replace(t.steps[0], params=params), t.steps[1])), cell).problems
    assert [(p.step, p.kind, p.parameter) for p in problems] == [(1, "bad_unit", "grip_force"),
                                                                 (1, "bad_unit", "speed")]
