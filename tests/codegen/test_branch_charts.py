"""Generated charts for branches on an outcome: W3C-valid, not unrolled, and the branch the device's outcome takes runs."""

from __future__ import annotations

import shutil
from pathlib import Path

from plugnproduce import service
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.codegen.outputs import all_charts
from plugnproduce.description.loader import load_device, parse_task
from plugnproduce.description.model import Cell, ProcessDescription
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart, schema_problems
from plugnproduce.statechart.model import walk
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.events import STATE_ENTERED, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter
from tests.codegen.conftest import bind_by_skill
from tests.conftest import edit

THEN_HOME = (descriptions_path() / "tasks" / "bin-picking-then-home.yaml").read_text(encoding="utf-8")


def generated_of(text: str, cell: Cell, processes: dict[str, ProcessDescription]):  # noqa: ANN201
    task = parse_task(text.encode(), "task.yaml")
    return generate_task(task, cell, bind_by_skill(task, cell, processes), processes, service.knowledge().taxonomy)


def size(chart: bytes) -> int:
    """How many elements the chart has."""
    return sum(1 for _ in walk(parse_chart(chart, "task.scxml")))


def test_every_chart_of_the_branching_task_is_w3c_valid(bin_picking_cell, processes) -> None:
    generated = generated_of(THEN_HOME, bin_picking_cell, processes)
    charts = all_charts(generated, bin_picking_cell, per_device=True)
    assert {c.kind for c in charts} == {"specific", "task", "closed-world", "device-program"}
    assert {c.name: schema_problems(c.data, c.name) for c in charts if schema_problems(c.data, c.name)} == {}


def test_the_chart_does_not_grow_with_the_number_of_iterations(bin_picking_cell, processes) -> None:
    few = generated_of(THEN_HOME.replace("max: 100", "max: 2"), bin_picking_cell, processes).task_chart()
    many = generated_of(THEN_HOME.replace("max: 100", "max: 100000"), bin_picking_cell, processes).task_chart()
    assert size(few) == size(many) and len(many) - len(few) == len("100000") - len("2")


def _entered_steps(chart: bytes) -> list[int]:
    """Run a closed-world chart in the project's runtime; the step charts it entered (``sN``: the chart first
    generated for position N), in order."""
    interpreter = Interpreter(parse_chart(chart, "closed-world.scxml"), clock=ManualClock())
    entered: list[int] = []

    def seen(meta: MetaEvent) -> None:
        state = str(meta.data.get("state", "")) if meta.name == STATE_ENTERED else ""
        if state[1:].isdigit() and state.startswith("s"):
            entered.append(int(state[1:]))

    interpreter.attach(seen)
    interpreter.start()
    for _ in range(100_000):
        if interpreter.execute_once() is None:
            break
    assert interpreter.final_state == "done"
    return entered


def test_the_branch_the_reported_outcome_takes_runs(tmp_path: Path, bin_picking_cell, processes) -> None:
    for f in ("binpicking-pc.ttl", "binpicking-pc.scxml"):
        shutil.copy(descriptions_path() / "devices" / f, tmp_path)
    edit(tmp_path / "binpicking-pc.scxml", """<data id="outcome" expr="'PartFound'"/>""",
         """<data id="outcome" expr="'BinEmpty'"/>""")
    empty = bin_picking_cell.with_device(load_device(tmp_path / "binpicking-pc.ttl", service.knowledge().taxonomy))
    generated = generated_of(THEN_HOME, empty, processes)
    # localize (1), its NoPartFound branch: move-to (4); the loop goes on only while parts are found
    assert _entered_steps(closed_world_chart(generated, empty)) == [1, 4]


def test_a_found_part_takes_the_other_branch(bin_picking_cell, processes) -> None:
    generated = generated_of(THEN_HOME.replace("max: 100", "max: 2"), bin_picking_cell, processes)
    # iteration 1: localize (1), pick (2), place (3); iteration 2: its own copy (5, 6; place 7 shares 3's chart)
    assert _entered_steps(closed_world_chart(generated, bin_picking_cell)) == [1, 2, 3, 5, 6, 3]
