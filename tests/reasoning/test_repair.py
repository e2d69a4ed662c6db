"""Repairs: optimal first, distinct next-best ones, configurable costs, devices from a catalogue."""

from __future__ import annotations

from dataclasses import replace

from plugnproduce import service
from plugnproduce.description.model import Cell
from plugnproduce.reasoning import RepairCosts
from tests.reasoning.conftest import task


def test_the_optimal_repair_inserts_open_gripper_before_step_2(cell: Cell) -> None:
    best = service.repair(task("bin-picking-invalid"), cell)[0]
    assert [(e.kind, e.step, e.command) for e in best.edits] == [("insert", 2, "open-gripper")]
    assert best.cost == 2.0
    assert [s.command for s in best.task.steps] == ["bin-pick", "open-gripper", "bin-pick", "place"]


def test_every_repair_is_plausible_and_distinct(cell: Cell) -> None:
    repairs = service.repair(task("bin-picking-invalid"), cell, top=4)
    assert [r.rank for r in repairs] == [1, 2, 3, 4]
    assert [r.cost for r in repairs] == sorted(r.cost for r in repairs)
    assert len({tuple(e.text for e in r.edits) for r in repairs}) == 4
    assert len({tuple(s.command for s in r.task.steps) for r in repairs}) == 4
    for r in repairs:
        assert service.check(r.task, cell).plausible, r.edits


def test_costs_are_configurable(cell: Cell) -> None:
    dear = RepairCosts(insert=10.0)
    best = service.repair(task("bin-picking-invalid"), cell, costs=dear)[0]
    assert [e.kind for e in best.edits] == ["swap"] and best.cost == 3.0


def test_a_plausible_task_needs_no_repair(cell: Cell) -> None:
    assert service.repair(task("bin-picking"), cell) == []


def test_a_device_is_added_from_the_catalogue_when_a_role_is_missing(cell: Cell) -> None:
    repairs = service.repair(task("bin-picking"), cell.without("gripper"), service.catalogue())
    best = repairs[0]
    assert best.added_devices == ("gripper",) and [e.kind for e in best.edits] == ["add"]
    assert best.cost == 5.18


def test_a_catalogue_does_not_change_repairs_that_are_cheaper_without_it(cell: Cell) -> None:
    with_catalogue = service.repair(task("bin-picking-invalid"), cell, service.catalogue())
    without = service.repair(task("bin-picking-invalid"), cell)
    assert [r.cost for r in with_catalogue] == [r.cost for r in without]


def test_a_value_out_of_range_is_reset(cell: Cell) -> None:
    t = task("pick-and-place")
    bad = replace(t, steps=(replace(t.steps[0], params={**t.steps[0].params, "grip_force": 500}), t.steps[1]))
    best = service.repair(bad, cell)[0]
    assert [(e.kind, e.parameter) for e in best.edits] == [("reset", "grip_force")]
    assert "grip_force" not in best.task.steps[0].params


def test_a_binding_to_an_absent_device_is_rebound(cell: Cell) -> None:
    t = task("pick-and-place")
    bad = replace(t, steps=(replace(t.steps[0], bind={"robot": "scara"}), t.steps[1]))
    best = service.repair(bad, cell)[0]
    assert [(e.kind, e.role, e.device) for e in best.edits] == [("rebind", "robot", "robot")]
    assert best.task.steps[0].bind == {"robot": "robot"}


def test_an_ambiguous_binding_is_settled_by_binding_it(cell: Cell, device) -> None:
    two = cell.with_device(device("vacuum-gripper"))
    best = service.repair(task("bin-picking"), two)[0]
    assert {(e.kind, e.role) for e in best.edits} == {("bind", "gripper")}
    assert service.check(best.task, two).plausible
