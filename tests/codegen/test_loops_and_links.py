"""Generated charts for loops and data links: W3C-valid, not unrolled, values carried in the datamodel."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.description.loader import load_device, parse_task
from plugnproduce.description.model import Cell, ProcessDescription
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart, schema_problems
from plugnproduce.statechart.model import Assign, Param, Transition, walk
from plugnproduce.statechart.runtime.evaluator import Evaluator
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


def rule_taken(chart: bytes, datamodel: dict[str, object]) -> list[tuple[str, str]]:
    """What the first loop or branch rule of the task chart's step picker that holds in ``datamodel`` assigns,
    its condition evaluated as the chart's interpreter does ([] when none holds)."""
    evaluator = Evaluator()
    for t in walk(parse_chart(chart, "task.scxml")):
        if isinstance(t, Transition) and any(v in (t.cond or "") for v in ("pnp_outcome", "pnp_rounds_", "pnp_branch_")):
            if evaluator.expr(t.cond or "").evaluate({"__builtins__": evaluator.builtins(), **datamodel}):
                return [(a.location, a.expr) for a in t.actions if isinstance(a, Assign)]
    return []


@pytest.mark.parametrize("until", ["BinEmpty", "NoPartFound"])
def test_an_outcome_under_the_loops_until_ends_it(until: str, bin_picking_cell, processes) -> None:
    # BinEmpty ⊑ NoPartFound; the body is localize, pick, place (positions 3-5 in its later iterations' copy)
    chart = chart_of(UNTIL_EMPTY.replace("until: BinEmpty", f"until: {until}"), bin_picking_cell, processes)
    localized = {"pnp_step": 4, "pnp_rounds_1": 1}
    assert rule_taken(chart, {**localized, "pnp_outcome": "BinEmpty"}) == [
        ("pnp_step", "6"), ("pnp_outcome", "None"), ("pnp_rounds_1", "-1")]
    assert rule_taken(chart, {**localized, "pnp_outcome": "PartFound"}) == []


def test_a_loop_goes_on_while_an_outcome_under_its_while_is_reported(bin_picking_cell, processes) -> None:
    # scan again while no part is found (BinEmpty ⊑ NoPartFound); the body's later iterations' copy is 3-5
    chart = chart_of(UNTIL_EMPTY.replace("until: BinEmpty", "while: NoPartFound"), bin_picking_cell, processes)
    iterated = {"pnp_step": 6, "pnp_rounds_1": 1}
    assert rule_taken(chart, {**iterated, "pnp_outcome": "BinEmpty"}) == [
        ("pnp_rounds_1", "pnp_rounds_1 + 1"), ("pnp_step", "3")]
    assert rule_taken(chart, {**iterated, "pnp_outcome": "PartFound"}) == [("pnp_outcome", "None"), ("pnp_rounds_1", "-1")]


def test_a_loop_of_at_most_one_iteration_skips_its_later_iterations_copy(bin_picking_cell, processes) -> None:
    # the body is localize, pick, place: its first iteration is positions 1-3, the later iterations' copy 4-6
    chart = chart_of(UNTIL_EMPTY.replace("max: 100", "max: 1"), bin_picking_cell, processes)
    assert rule_taken(chart, {"pnp_step": 3, "pnp_rounds_1": 0, "pnp_outcome": "PartFound"}) == [
        ("pnp_step", "6"), ("pnp_rounds_1", "-1")]


def test_the_outcome_of_the_loops_first_step_ends_it(bin_picking_cell, processes) -> None:
    chart = chart_of(UNTIL_EMPTY, bin_picking_cell, processes)
    assert rule_taken(chart, {"pnp_step": 1, "pnp_rounds_1": 0, "pnp_outcome": "BinEmpty"}) == [
        ("pnp_step", "6"), ("pnp_outcome", "None"), ("pnp_rounds_1", "-1")]
    assert rule_taken(chart, {"pnp_step": 0, "pnp_rounds_1": 0, "pnp_outcome": "BinEmpty"}) == []
