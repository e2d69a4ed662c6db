"""Side effects of repairs: a repair that drops the part the gripper holds ranks below those that do not."""

from __future__ import annotations

from pathlib import Path

from plugnproduce import service
from plugnproduce.description.model import Cell, Step, Task
from plugnproduce.reasoning.sideeffects import new_steps
from tests.reasoning.conftest import TASKS, task

INVALID = TASKS / "bin-picking-invalid.yaml"


def test_the_repair_that_opens_the_holding_gripper_states_it_drops_the_part(cell: Cell) -> None:
    repairs = service.assessed_repairs(INVALID, cell)
    opening = next(r for r in repairs if any(e.command == "open-gripper" for e in r.repair.edits))
    drop = next(e for e in opening.side_effects if e.kind == "drops_part")
    assert drop.device == "gripper" and drop.step == 2
    assert "holds the part step 1 (bin-pick) picked" in drop.text and "device 'robot' stands" in drop.text


def test_a_repair_that_drops_a_part_ranks_below_those_that_do_not(cell: Cell) -> None:
    repairs = service.assessed_repairs(INVALID, cell)
    assert [r.rank for r in repairs] == list(range(1, len(repairs) + 1))
    dropping = [r.rank for r in repairs if any(e.kind == "drops_part" for e in r.side_effects)]
    keeping = [r.rank for r in repairs if not any(e.kind == "drops_part" for e in r.side_effects)]
    assert dropping and keeping and max(keeping) < min(dropping)
    assert all(r.confirmed for r in repairs)


def test_the_cheapest_repair_keeps_its_solver_rank_in_the_json(cell: Cell) -> None:
    repairs = service.assessed_repairs(INVALID, cell)
    doc = next(r.to_json() for r in repairs if r.repair.rank == 1)
    assert doc["solver_rank"] == 1 and doc["rank"] == len(repairs) and doc["side_effects"]


def test_a_reorder_that_leaves_a_part_in_the_gripper_says_so(cell: Cell) -> None:
    repairs = service.assessed_repairs(INVALID, cell)
    swap = next(r for r in repairs if any(e.kind == "swap" for e in r.repair.edits))
    assert [e.kind for e in swap.side_effects] == ["ends_holding"]


def test_an_inserted_step_is_found_before_the_steps_it_shifts() -> None:
    original = task("bin-picking-invalid")
    steps = list(original.steps)
    repaired = Task(original.name, (steps[0], Step(2, "place"), *steps[1:]), original.file)
    assert new_steps(original, repaired) == {2}
    assert new_steps(original, original) == set()


def test_a_dropped_part_rests_on_the_pick_process_and_the_gripper_states(cell: Cell) -> None:
    repairs = service.assessed_repairs(INVALID, cell)
    opening = next(r for r in repairs if any(e.command == "open-gripper" for e in r.repair.edits))
    tree = opening.derivation
    assert tree.text.endswith("makes the task plausible") and tree.children[0].where is not None
    drop = next(n for n in tree.children if n.detail == "drops_part")
    assert [n.kind for n in drop.children] == ["owl", "chart", "chart", "owl"]
    lines = [Path(n.where.file).read_text(encoding="utf-8").splitlines()[(n.where.line or 0) - 1]
             for n in drop.children if n.where]
    assert "proc:bin-pick a pnp:PickProcess" in lines[0] and 'id="closed"' in lines[1] and 'id="open"' in lines[2]
