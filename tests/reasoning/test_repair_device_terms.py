"""Repairs keep the devices' own terms and the values as written, and are ranked in their documented order.

Found on cells a cell integrator wrote in their own library (tests/data/libraries/gentle-tending, over the
machine-tending library): a repair bought a catalogue vacuum gripper whose 20 kPa minimum refuses the task's
15 kPa, and ``pnp run`` then refused that cell; values written with units (``70 %``, ``60 kPa``) were reset
to their defaults while the same plain numbers were kept; and a cost-8 removal ranked above a cheaper purchase
with no side effect on either.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.description.model import Cell
from plugnproduce.reasoning import AssessedRepair
from plugnproduce.reasoning.repairs.sideeffects import ranking
from tests.reasoning.conftest import BIN_PICKING

LIBRARIES = Path(__file__).parents[1] / "data" / "libraries"
GENTLE = LIBRARIES / "gentle-tending"
WITHOUT_GRIPPER = GENTLE / "cells" / "tending-without-gripper.yaml"
GENTLE_TASK = GENTLE / "tasks" / "gentle-tending.yaml"
DOOR_SHUT = GENTLE / "tasks" / "tending-door-shut.yaml"
TENDING = LIBRARIES / "machine-tending" / "cells" / "machine-tending.yaml"
BUILTIN_DEVICES = service.builtin("devices")


@pytest.fixture(scope="module")
def knowledge() -> service.Knowledge:
    return service.knowledge_for_cell(WITHOUT_GRIPPER)


@pytest.fixture(scope="module")
def purchases(knowledge: service.Knowledge) -> list[AssessedRepair]:
    return service.assessed_repairs(GENTLE_TASK, WITHOUT_GRIPPER, BUILTIN_DEVICES, 3, knowledge)


def _with_added(cell: Cell, repair: AssessedRepair, knowledge: service.Knowledge) -> Cell:
    added = tuple(d for d in service.catalogue(BUILTIN_DEVICES, knowledge) if d.id in repair.repair.added_devices)
    return dataclasses.replace(cell, devices=cell.devices + added)


def test_every_repair_proposed_is_plausible_with_the_devices_it_buys(purchases: list[AssessedRepair],
                                                                       knowledge: service.Knowledge) -> None:
    cell = service.cell(WITHOUT_GRIPPER, knowledge)
    assert purchases and any(r.repair.added_devices for r in purchases)
    for r in purchases:
        result = service.check(r.repair.task, _with_added(cell, r, knowledge), knowledge)
        assert result.plausible, (r.repair.edits, result.problems)


def test_the_vacuum_gripper_is_bought_with_the_vacuum_its_limit_takes_and_says_why(
        purchases: list[AssessedRepair], knowledge: service.Knowledge) -> None:
    bought = next(r for r in purchases if r.repair.added_devices == ("vacuum-gripper",))
    resets = [e.text for e in bought.repair.edits if e.kind == "reset"]
    assert resets == [f"step {i} ({c}): reset parameter vacuum to its default 60 (device 'vacuum-gripper' takes at "
                      f"least 20 kPa; the value is 15 kPa)" for i, c in ((2, "load-machine"), (6, "unload-machine"))]
    steps = bought.repair.task.steps
    assert "vacuum" not in steps[1].params and steps[1].params["speed"] == "70 %"
    # what pnp run does before any command goes out: check and generate it in the cell with the device bought
    generated = service.plan_run(bought.repair.task, _with_added(service.cell(WITHOUT_GRIPPER, knowledge), bought,
                                                                 knowledge), knowledge)
    assert generated.task.name == "gentle-tending"


def test_repairs_rank_by_worst_side_effect_then_cost(purchases: list[AssessedRepair]) -> None:
    assert [r.rank for r in purchases] == [1, 2, 3]
    assert [ranking(r) for r in purchases] == sorted(ranking(r) for r in purchases)
    assert purchases[0].repair.added_devices == ("vacuum-gripper",) and purchases[0].repair.cost == 9.09
    assert [e.kind for e in purchases[1].repair.edits] == ["remove"] * 3 and purchases[1].repair.cost == 12


def test_a_rebound_step_runs_with_no_default_it_did_not_run_with_before(purchases: list[AssessedRepair]) -> None:
    assert all(not r.side_effects for r in purchases[:2])


def test_values_written_with_units_survive_the_repair_of_a_library_task() -> None:
    knowledge = service.knowledge_for_cell(TENDING)
    repairs = service.assessed_repairs(DOOR_SHUT, TENDING, None, 3, knowledge)
    assert [e.text for e in repairs[0].repair.edits] == ["insert open-door before step 1 (load-machine)"]
    assert not any(e.kind == "reset" for r in repairs for e in r.repair.edits)
    load = next(s for s in repairs[0].repair.task.steps if s.command == "load-machine")
    assert (load.params["vacuum"], load.params["speed"]) == ("60 kPa", "70 %")


UNITS = """task: units
steps:
  - command: bin-pick
    params: {grip_force: "80 N", speed: "40 %"}
  - command: bin-pick
    params: {grip_force: 80, speed: 40}
  - command: place
"""


def test_values_written_with_units_survive_repair_and_explain_as_plain_numbers_do(tmp_path: Path) -> None:
    task = tmp_path / "units.yaml"
    task.write_text(UNITS, encoding="utf-8")
    repairs = service.assessed_repairs(task, BIN_PICKING)
    assert repairs and not any(e.kind == "reset" for r in repairs for e in r.repair.edits)
    assert all(r.repair.task.steps[0].params == {"grip_force": "80 N", "speed": "40 %"} for r in repairs
               if r.repair.task.steps[0].command == "bin-pick")
    why = service.explain_plausible(task, BIN_PICKING, 2)
    edits = [c.text for c in why.counterfactuals if c.kind == "edit_task"]
    assert "insert open-gripper before step 2 (bin-pick)" in edits and not any("reset" in e for e in edits)


def test_the_cli_proposes_the_purchase_with_the_vacuum_reset_first() -> None:
    result = CliRunner().invoke(app, ["repair", str(GENTLE_TASK), "--cell", str(WITHOUT_GRIPPER), "--catalogue",
                                      str(BUILTIN_DEVICES), "--json"])
    assert result.exit_code == 0, result.output
    repairs = json.loads(result.stdout)["repairs"]
    assert [r["rank"] for r in repairs] == [1, 2, 3] and all(r["confirmed"] for r in repairs)
    assert repairs[0]["added_devices"] == ["vacuum-gripper"] and repairs[0]["cost"] == 9.09
    assert [e["parameter"] for e in repairs[0]["edits"] if e["kind"] == "reset"] == ["vacuum", "vacuum"]


def test_a_long_task_repaired_window_by_window_keeps_the_bought_grippers_limit_and_says_why(tmp_path: Path) -> None:
    cell = tmp_path / "no-gripper.yaml"
    cell.write_text("cell: no-gripper\ndevices: [robot, sensor3d, binpicking-pc]\n", encoding="utf-8")
    pair = "  - command: bin-pick\n    params: {grip_force: 120}\n  - command: place\n"
    task = tmp_path / "long.yaml"
    task.write_text("task: long\nsteps:\n" + 21 * pair, encoding="utf-8")  # 42 steps: window by window
    repairs = service.assessed_repairs(task, cell, BUILTIN_DEVICES, 2)
    bought = next(r for r in repairs if r.repair.added_devices == ("gripper",))
    resets = [e.text for e in bought.repair.edits if e.kind == "reset"]
    assert len(resets) == 21 and resets[0] == ("step 1 (bin-pick): reset parameter grip_force to its default 40 "
                                               "(device 'gripper' takes at most 100 N; the value is 120 N)")
