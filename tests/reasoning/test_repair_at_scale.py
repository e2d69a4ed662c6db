"""Repair of long tasks with many faults: each fault gets its cheapest fix, the whole-task solver agrees on a
medium task, and the repaired tasks are checked again from the task's own check (same answer as a whole check)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from plugnproduce import service
from plugnproduce.description.model import Cell, Loop, Step, Task
from plugnproduce.reasoning.checks.plausibility import check
from plugnproduce.reasoning.checks.recheck import Moves, recheck
from plugnproduce.reasoning.repairs import repairs, windows
from tests.reasoning.faulty_tasks import faulty_task

KNOWLEDGE = service.knowledge()
MACHINE_TENDING = Path(__file__).parents[1] / "data" / "libraries" / "machine-tending"


def joined(parts: list[Task]) -> tuple[Task, list[range]]:
    """One task of the parts one after the other, and the step numbers each part has in it."""
    steps, spans = [], []
    for part in parts:
        spans.append(range(len(steps) + 1, len(steps) + len(part.steps) + 1))
        steps += part.steps
    return Task("long", tuple(dataclasses.replace(st, index=n) for n, st in enumerate(steps, start=1)),
                "long.yaml"), spans


def test_a_long_task_with_many_faults_gets_each_faults_cheapest_fix(cell: Cell) -> None:
    # 40 stretches of 5 pick-and-place pairs, one fault each (of every kind), each stretch ending where it began
    parts = [faulty_task(5, 1, seed, varied=True) for seed in range(40)]
    task, spans = joined(parts)
    assert len(service.check(task, cell).problems) >= 40
    best = windows.windowed_repair(task, cell, KNOWLEDGE, top=1)[0]
    cheapest = [repairs.repair(part, cell, KNOWLEDGE, top=1)[0].cost for part in parts]  # each fault alone
    assert all(c > 0 for c in cheapest)
    for span, cost in zip(spans, cheapest, strict=True):
        assert sum(e.cost for e in best.edits if e.step in span) == cost
    assert best.cost == sum(cheapest)
    assert service.check(best.task, cell).plausible


def test_the_whole_task_solver_finds_repairs_as_cheap_on_a_medium_task(cell: Cell) -> None:
    task = faulty_task(60, 8, 11, varied=True)  # 120 steps: the whole-task solver still answers quickly
    found = windows.windowed_repair(task, cell, KNOWLEDGE, top=3)
    reference = repairs.repair(task, cell, KNOWLEDGE, top=3)
    assert [r.cost for r in found] == [r.cost for r in reference]  # the three cheapest, in order
    assert all(service.check(r.task, cell).plausible for r in found + reference)


def test_a_repaired_long_task_checked_from_its_own_check_is_checked_as_a_whole_would_be(cell: Cell) -> None:
    task = faulty_task(400, 8, 5, varied=True)
    before = check(task, cell, KNOWLEDGE)
    moves = Moves(cell, KNOWLEDGE, task, before)
    for r in windows.windowed_repair(task, cell, KNOWLEDGE, top=3):
        assert recheck(r.task, moves) == check(r.task, cell, KNOWLEDGE)  # steps, bindings, states, final states
    assert 0 < moves.checked_again < len(task.steps) // 4  # only the steps around the edits were checked again


def test_a_repaired_task_that_is_still_implausible_is_left_to_the_whole_check(cell: Cell) -> None:
    task = faulty_task(100, 3, 5)
    moves = Moves(cell, KNOWLEDGE, task, check(task, cell, KNOWLEDGE))
    best = windows.windowed_repair(task, cell, KNOWLEDGE, top=1)[0]
    assert recheck(best.task, moves) is not None
    broken = dataclasses.replace(best.task, steps=tuple(
        dataclasses.replace(st, command="move-to", params={}) if n == 70 else st
        for n, st in enumerate(best.task.steps, start=1)))
    assert not check(broken, cell, KNOWLEDGE).plausible
    assert recheck(broken, moves) is None


def test_a_task_with_a_loop_is_not_checked_from_moves(cell: Cell) -> None:
    task = faulty_task(30, 2, 5)
    moves = Moves(cell, KNOWLEDGE, task, check(task, cell, KNOWLEDGE))
    best = windows.windowed_repair(task, cell, KNOWLEDGE, top=1)[0]
    looped = dataclasses.replace(best.task, loops=(Loop(1, 3, 4, None, 2),))
    assert recheck(looped, moves) is None


def test_a_long_task_of_a_library_outside_the_package_is_checked_again_from_its_own_check() -> None:
    cell_file = MACHINE_TENDING / "cells" / "machine-tending.yaml"
    knowledge, cell = service.knowledge_for_cell(cell_file), service.cell(cell_file)
    close = Step(0, "close-door")
    cycle = [*service.task(MACHINE_TENDING / "tasks" / "machine-tending.yaml").steps, close]
    door_open = [*service.task(MACHINE_TENDING / "tasks" / "machining-door-open.yaml").steps, close]
    task, _ = joined([Task("cycle", tuple(steps), "t.yaml") for steps in
                      (cycle * 4, door_open, cycle * 4, door_open, cycle * 3)])  # 89 steps: repaired in windows
    before = check(task, cell, knowledge)
    assert [(p.step, p.kind) for p in before.problems] == [(31, "wrong_state"), (65, "wrong_state")]
    moves = Moves(cell, knowledge, task, before)
    found = windows.repair(task, cell, knowledge, top=3)
    assert [e.text for e in found[0].edits] == ["insert close-door before step 31 (machine)",
                                                "insert close-door before step 65 (machine)"]
    for r in found:
        again = recheck(r.task, moves)
        assert again is not None and again.plausible
        assert again == check(r.task, cell, knowledge)
    assert moves.checked_again < 10
