"""Generated charts for loops and data links: W3C-valid, not unrolled, values carried in the datamodel."""

from __future__ import annotations

import shutil
from pathlib import Path

from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.description.loader import load_device, parse_task
from plugnproduce.description.model import Cell, ProcessDescription
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart, schema_problems
from plugnproduce.statechart.model import Assign, Param, walk
from tests.codegen.conftest import bind_by_skill
from tests.conftest import edit

UNTIL_EMPTY = (descriptions_path() / "tasks" / "bin-picking-until-empty.yaml").read_text(encoding="utf-8")


def chart_of(text: str, cell: Cell, processes: dict[str, ProcessDescription]) -> bytes:
    task = parse_task(text.encode(), "task.yaml")
    generated = generate_task(task, cell, bind_by_skill(task, cell, processes), processes,
                              service.knowledge().taxonomy)
    return generated.task_chart()


def size(chart: bytes) -> int:
    """How many elements the chart has."""
    return sum(1 for _ in walk(parse_chart(chart, "task.scxml")))


def test_the_until_empty_chart_is_w3c_valid(bin_picking_cell, processes) -> None:
    chart = chart_of(UNTIL_EMPTY, bin_picking_cell, processes)
    assert schema_problems(chart, "task.scxml") == []


def test_the_chart_does_not_grow_with_the_number_of_iterations(bin_picking_cell, processes) -> None:
    few = chart_of(UNTIL_EMPTY.replace("max: 100", "max: 2"), bin_picking_cell, processes)
    many = chart_of(UNTIL_EMPTY.replace("max: 100", "max: 100000"), bin_picking_cell, processes)
    assert size(few) == size(many) and len(many) - len(few) == len("100000") - len("2")


def test_the_localised_pose_is_kept_and_sent_to_the_robot(bin_picking_cell, processes) -> None:
    chart = parse_chart(chart_of(UNTIL_EMPTY, bin_picking_cell, processes), "task.scxml")
    kept = {(a.location, a.expr) for a in walk(chart) if isinstance(a, Assign) and a.location.startswith("pnp_out_")}
    sent = {p.expr for p in walk(chart) if isinstance(p, Param) and p.name == "TargetPose"}
    assert kept == {("pnp_out_localize_part_pose", "_event.data.part_pose")}
    assert "pnp_out_localize_part_pose" in sent


def run(chart: bytes) -> set[str]:
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", chart.decode())
    return set(processor.start().configuration_values)


def test_the_loop_ends_on_the_outcome_the_device_reports(tmp_path: Path, bin_picking_cell, processes) -> None:
    for f in ("binpicking-pc.ttl", "binpicking-pc.scxml"):
        shutil.copy(descriptions_path() / "devices" / f, tmp_path)
    edit(tmp_path / "binpicking-pc.scxml", """<data id="outcome" expr="'PartFound'"/>""",
         """<data id="outcome" expr="'BinEmpty'"/>""")
    empty = bin_picking_cell.with_device(load_device(tmp_path / "binpicking-pc.ttl", service.knowledge().taxonomy))
    endless = UNTIL_EMPTY.replace("      max: 100\n", "")  # only the outcome can end it now
    task = parse_task(endless.encode(), "task.yaml")
    generated = generate_task(task, empty, bind_by_skill(task, empty, processes), processes,
                              service.knowledge().taxonomy)
    assert run(closed_world_chart(generated, empty)) == {"done"}
