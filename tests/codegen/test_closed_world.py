"""Closed-world simulation charts run in an independent SCXML interpreter (python-statemachine)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.description.loader import load_device
from plugnproduce.resources import descriptions_path
from tests.codegen.conftest import generate
from tests.conftest import edit

VALID_TASKS = ["bin-picking", "bin-picking-in-rounds", "bin-picking-localized", "bin-picking-then-home",
               "bin-picking-until-empty",
               "pick-and-place"]
OTHER_CELLS = {"pick-and-screw": "mixed"}
"""Tasks of a built-in cell other than bin-picking: the task and its cell."""


def run(chart: bytes) -> set[str]:
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", chart.decode())
    machine = processor.start()
    return set(machine.configuration_values)


@pytest.mark.parametrize("task", VALID_TASKS)
def test_closed_world_chart_reaches_done(task, bin_picking_cell, processes) -> None:
    generated = generate(task, bin_picking_cell, processes)
    assert run(closed_world_chart(generated, bin_picking_cell)) == {"done"}


@pytest.mark.parametrize("task", OTHER_CELLS)
def test_closed_world_chart_of_another_cell_reaches_done(task, processes) -> None:
    """The mixed cell's task (XIRP, UPnP and OPC UA devices): its OPC UA requests are plain events there too."""
    cell = service.cell(service.builtin("cells", f"{OTHER_CELLS[task]}.yaml"))
    assert run(closed_world_chart(generate(task, cell, processes), cell)) == {"done"}


def test_every_builtin_valid_task_is_covered() -> None:
    names = {p.stem for p in (descriptions_path() / "tasks").glob("*.yaml")}
    assert names - {"bin-picking-invalid"} == set(VALID_TASKS) | set(OTHER_CELLS)


def test_broken_device_model_does_not_reach_done(tmp_path: Path, bin_picking_cell, processes) -> None:
    for f in ("gripper.ttl", "gripper.scxml"):
        shutil.copy(descriptions_path() / "devices" / f, tmp_path)
    # The program is generated for the real gripper, but the model it runs against never
    # reports that it closed: the controller waits until the gripper's command timeout fires.
    edit(tmp_path / "gripper.scxml", '<send event="xirp.event.gripper_closed" type="xirp"/>', "")
    broken = load_device(tmp_path / "gripper.ttl", service.knowledge().taxonomy)
    generated = generate("bin-picking", bin_picking_cell, processes)
    configuration = run(closed_world_chart(generated, bin_picking_cell.with_device(broken)))
    assert configuration == {"failed"}


def test_a_hierarchical_device_chart_runs_in_the_closed_world_chart() -> None:
    """The PackML-style screwdriver (compound states, a superstate's Abort) as a responding region: its nested
    states and their initial children renamed with it, and the independent interpreter reaches done."""
    library = Path(__file__).parents[1] / "data" / "libraries" / "packml-screwing"
    cell = service.cell(library / "cells" / "packml-screwing.yaml")
    generated = service.generate(library / "tasks" / "screw-twice.yaml", cell)
    world = next(c.data for c in generated.charts if c.name.endswith(".closed-world.scxml"))
    assert b'initial="packml_screwdriver__Starting"' in world  # Running's initial child, renamed
    assert run(world) == {"done"}
