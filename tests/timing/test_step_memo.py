"""The repairs' cycle times estimate the steps they share once (:class:`StepMemo`), and give exactly what each
repaired task's own estimate gives: on the built-in cell, on the timed-cell library, and where a step has the
same chart and values as one seen but its robot starts from another pose (estimated again, not reused)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from plugnproduce import service
from plugnproduce.timing.estimate import StepMemo
from plugnproduce.timing.tasks import task_cycle_time
from tests.reasoning.faulty_tasks import faulty_task

ROOT = Path(__file__).parents[2]
TIMED = ROOT / "tests" / "data" / "libraries" / "timed-cell"


def whole_estimates(repairs: list[service.reasoning.AssessedRepair], cell: service.Cell,
                    k: service.Knowledge) -> list[object]:
    """Each repaired task estimated on its own, from its own check (no memo)."""
    return [None if (t := service.cycle_time(r.repair.task, cell, k)) is None else t.to_json() for r in repairs]


def test_the_repairs_of_a_long_task_in_the_builtin_cell_estimate_as_each_one_alone() -> None:
    cell, k = service.cell_and_knowledge(service.builtin("cells", "bin-picking.yaml"), None)
    task = faulty_task(60, 2, 1, varied=True)
    repairs = service.assessed_repairs(task, cell, None, 3, k)
    assert len(repairs) == 3
    memo = [t.to_json() if t is not None else None for t in service.repair_cycle_times(repairs, cell, None, k)]
    assert memo == whole_estimates(repairs, cell, k)
    assert all(t is not None and len(t["steps"]) >= 120 for t in memo)


def test_the_repair_of_a_library_task_estimates_as_alone() -> None:
    """A pick-and-place faster than the timed-cell robot allows: its repairs, timed by the declared motion."""
    cell, k = service.cell_and_knowledge(TIMED / "cells" / "timed-cell.yaml", None)
    task = service.task(TIMED / "tasks" / "pick-place-timed.yaml")
    fast = dataclasses.replace(task.steps[1], params={**task.steps[1].params, "speed": 150})
    too_fast = dataclasses.replace(task, steps=(task.steps[0], fast, task.steps[2]))
    repairs = service.assessed_repairs(too_fast, cell, None, 3, k)
    assert repairs
    memo = [t.to_json() if t is not None else None for t in service.repair_cycle_times(repairs, cell, None, k)]
    assert memo == whole_estimates(repairs, cell, k)
    assert all(t is not None and t["total_seconds"] > 0 for t in memo)


def test_a_step_whose_robot_starts_from_another_pose_is_estimated_again() -> None:
    """The same pick-and-place after a move to another pose: same chart, same values, another approach distance."""
    cell, k = service.cell_and_knowledge(TIMED / "cells" / "timed-cell.yaml", None)
    task = service.task(TIMED / "tasks" / "pick-place-timed.yaml")
    elsewhere = dataclasses.replace(task.steps[0], params={**task.steps[0].params,
                                                            "target_pose": [0.40, 0.30, 0.40, 0, 180, 0]})
    moved = dataclasses.replace(task, steps=(elsewhere, *task.steps[1:]))
    memo = StepMemo()
    first = task_cycle_time(task, cell, k, memo=memo)
    second = task_cycle_time(moved, cell, k, memo=memo)
    alone = task_cycle_time(moved, cell, k)
    assert first is not None and second is not None and alone is not None
    assert second.to_json() == alone.to_json()
    assert second.steps[1].seconds != first.steps[1].seconds  # 0.4 m to the pick pose, not 0.5 m
    again = task_cycle_time(task, cell, k, memo=memo)
    assert again is not None and again.to_json() == first.to_json()
