"""Side effects of repairs: a repair that drops the part the gripper holds ranks below those that do not."""

from __future__ import annotations

import dataclasses
import random
from pathlib import Path

from plugnproduce import service
from plugnproduce.description.model import Cell, Step, Task
from plugnproduce.reasoning.repairs.sideeffects import new_steps
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


def _new_steps_by_table(original: Task, repaired: Task) -> set[int]:
    """The steps new in ``repaired`` as the whole longest-common-subsequence table finds them (the reference)."""
    sig = [(s.command, tuple(sorted(s.bind.items())), tuple(sorted((k, str(v)) for k, v in s.params.items())))
           for s in original.steps]
    new = [(s.command, tuple(sorted(s.bind.items())), tuple(sorted((k, str(v)) for k, v in s.params.items())))
           for s in repaired.steps]
    n, m = len(sig), len(new)
    lcs = [[0] * (m + 1) for _ in range(n + 1)]
    for i in range(n):
        for j in range(m):
            lcs[i + 1][j + 1] = lcs[i][j] + 1 if sig[i] == new[j] else max(lcs[i][j + 1], lcs[i + 1][j])
    fresh, i, j = set(), n, m
    while j > 0:
        if i > 0 and sig[i - 1] == new[j - 1] and lcs[i][j] == lcs[i - 1][j - 1] + 1:
            i, j = i - 1, j - 1
        elif i > 0 and lcs[i - 1][j] == lcs[i][j]:
            i -= 1
        else:
            fresh.add(j)
            j -= 1
    return fresh


def test_new_steps_of_long_repaired_tasks_are_those_the_whole_table_finds() -> None:
    """Repeated steps (bin-pick, place, ...) with steps inserted, moved, dropped and changed at random: the
    steps called new are the reference's, step for step."""
    rng = random.Random(28)
    kinds = [Step(0, "bin-pick"), Step(0, "place"), Step(0, "open-gripper"), Step(0, "place", params={"speed": 20}),
             Step(0, "move-to", bind={"robot": "robot"})]
    for _ in range(60):
        steps = [kinds[n % 2] for n in range(rng.randint(0, 120))]
        edited = list(steps)
        for _ in range(rng.randint(0, 8)):
            at = rng.randint(0, len(edited))
            what = rng.choice(["insert", "drop", "move", "change"])
            if what == "insert" or not edited:
                edited.insert(at, rng.choice(kinds))
            elif what == "drop":
                edited.pop(min(at, len(edited) - 1))
            elif what == "move":
                edited.insert(rng.randint(0, len(edited) - 1), edited.pop(min(at, len(edited) - 1)))
            else:
                edited[min(at, len(edited) - 1)] = rng.choice(kinds)
        original = Task("t", tuple(dataclasses.replace(s, index=n + 1) for n, s in enumerate(steps)), "t.yaml")
        repaired = Task("t", tuple(dataclasses.replace(s, index=n + 1) for n, s in enumerate(edited)), "t.yaml")
        assert new_steps(original, repaired) == _new_steps_by_table(original, repaired)
