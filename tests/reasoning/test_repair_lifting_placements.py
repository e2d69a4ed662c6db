"""Lifting a repair onto the written task, from repairs made by hand: the copies of a loop body repaired with other
values, the places an inserted step may go at the very start of a task, and the bound on the placements checked."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.model import Cell, Step, Task
from plugnproduce.reasoning import CheckResult, Repair
from plugnproduce.reasoning.repairs import lifting
from plugnproduce.reasoning.repairs.lifting import MAX_PLACEMENTS, UNROLLS, lift
from tests.reasoning.conftest import BIN_PICKING, TASKS

SCAN = """  - loop:
      until: BinEmpty
      max: 3
      steps:
        - command: localize-part
          bind: {sensor: sensor3d, localizer: binpicking-pc}
          params: {exposure: 25, part_type: bracket}
"""
FOUR_SCANS = "task: four-scans\nsteps:\n" + SCAN * 4
"""Four loops in a row, each of one step: flat, steps 1-2, 3-4, 5-6 and 7-8."""


def _flat_repair(task: Task, steps: list[tuple[int, Step]]) -> Repair:
    """A repair as the repairer gives one: its flat steps, each with the written position it keeps (0: inserted)."""
    flat = tuple(dataclasses.replace(s, index=i) for i, (_, s) in enumerate(steps, start=1))
    return Repair(1, 1.0, (), dataclasses.replace(task, steps=flat, loops=(), branches=()),
                  origins=tuple(q for q, _ in steps))


def _scan_bin(task: Task) -> Step:
    return dataclasses.replace(task.steps[0], command="scan-bin", bind={}, params={}, name=None)


def _placements_checked(monkeypatch: pytest.MonkeyPatch) -> list[Task]:
    """The written tasks lift asks the check about; the check finds each not plausible (with a real problem)."""
    problem = service.check(service.task(TASKS / "bin-picking-invalid.yaml"), BIN_PICKING).problems[0]
    asked: list[Task] = []

    def check(task: Task, cell: Cell, knowledge: object) -> CheckResult:
        asked.append(task)
        return CheckResult(task.name, cell.name, False, (problem,), ())

    monkeypatch.setattr(lifting, "check", check)
    return asked


def test_loop_copies_repaired_with_different_values_keep_their_flat_steps() -> None:
    """The first iteration picks with 40 N and the second with 50 N: no written step says both."""
    task = service.task(TASKS / "bin-picking-until-empty.yaml")
    cell, knowledge = service.cell_and_knowledge(BIN_PICKING, None)
    forces = {2: 40, 5: 50}
    steps = [(q, dataclasses.replace(s, params={**s.params, "grip_force": forces[q]}) if q in forces else s)
             for q, s in enumerate(task.steps, start=1)]
    r = lift(_flat_repair(task, steps), task, cell, knowledge)
    assert r.unrolls == UNROLLS + "the iterations of the loop repair step 2 (pick) differently"
    assert r.task.loops == () and [s.params.get("grip_force") for s in r.task.steps] == [None, 40, None, None, 50,
                                                                                          None]
    same = [(q, dataclasses.replace(s, params={**s.params, "grip_force": 40}) if q in forces else s)
            for q, s in enumerate(task.steps, start=1)]
    r = lift(_flat_repair(task, same), task, cell, knowledge)
    assert r.unrolls is None and r.task.loops == task.loops and r.task.steps[1].params["grip_force"] == 40


def test_a_step_inserted_before_a_first_one_step_loop_goes_into_its_body_or_before_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Inserted before everything, the scan goes before the loop's step or before the loop: not after the loop's
    step, which the flat order does not say."""
    (tmp_path / "task.yaml").write_text(FOUR_SCANS, encoding="utf-8")
    task = service.task(tmp_path / "task.yaml")
    cell, knowledge = service.cell_and_knowledge(BIN_PICKING, None)
    asked = _placements_checked(monkeypatch)
    repair = _flat_repair(task, [(0, _scan_bin(task)), *enumerate(task.steps, start=1)])
    r = lift(repair, task, cell, knowledge)
    assert r.unrolls is not None and r.unrolls.startswith(UNROLLS + "kept in the loop or branch it is not plausible")
    assert [([s.command for s in t.steps[:3]], [(lp.entry, lp.first, lp.last) for lp in t.loops[:1]])
            for t in asked] == [(["scan-bin", "localize-part", "scan-bin"], [(1, 3, 4)]),
                                (["scan-bin", "localize-part", "localize-part"], [(2, 3, 3)])]


def test_at_most_sixteen_placements_are_checked(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A scan inserted between each two loops may go at the end of the loop before it, before the loop after it or
    into that loop's body: 27 placements, of which the first 16 are checked."""
    (tmp_path / "task.yaml").write_text(FOUR_SCANS, encoding="utf-8")
    task = service.task(tmp_path / "task.yaml")
    cell, knowledge = service.cell_and_knowledge(BIN_PICKING, None)
    asked = _placements_checked(monkeypatch)
    flat: list[tuple[int, Step]] = []
    for q, s in enumerate(task.steps, start=1):
        flat += [(0, _scan_bin(task))] if q in (3, 5, 7) else []
        flat.append((q, s))
    r = lift(_flat_repair(task, flat), task, cell, knowledge)
    assert r.unrolls is not None and r.unrolls.startswith(UNROLLS + "kept in the loop or branch it is not plausible")
    assert MAX_PLACEMENTS == 16 and len(asked) == 16
    assert len({(tuple(s.command for s in t.steps), t.loops) for t in asked}) == 16  # each a placement of its own
