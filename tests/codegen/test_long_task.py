"""Long tasks: identical step charts are generated and written once, and the output stays valid."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.resources import descriptions_path
from plugnproduce.safeio import MAX_BYTES
from plugnproduce.statechart import PNP_NS, Parallel, parse_chart
from plugnproduce.statechart.model import Send, walk
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.events import ERROR, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.validation.validate import validate_paths

STEPS = 2000
"""The longest task ``repeat`` allows (1,000 rounds of two steps). Unrolled, its closed-world chart was larger than
``pnp validate`` accepts, and its plan was once an expression too long for the runtime to evaluate."""


@pytest.fixture(scope="module")
def long_task(tmp_path_factory: pytest.TempPathFactory) -> Path:
    text = (descriptions_path() / "tasks" / "bin-picking.yaml").read_text(encoding="utf-8")
    path = tmp_path_factory.mktemp("long") / "bin-picking-long.yaml"
    path.write_text(text.replace("repeat: 3", f"repeat: {STEPS // 2}"), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def written(long_task: Path, tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    cell = service.cell(descriptions_path() / "cells" / "bin-picking.yaml")
    out = tmp_path_factory.mktemp("out")
    files = []
    for chart in service.generate(long_task, cell).charts:
        (out / chart.name).write_bytes(chart.data)
        files.append(out / chart.name)
    return files


def test_identical_specific_charts_are_written_once(written: list[Path]) -> None:
    specific = sorted(f.name for f in written if f.name.startswith("step"))
    assert specific == ["step01-bin-pick.scxml", "step02-place.scxml", "step03-bin-pick.scxml"]


def test_every_step_of_the_task_chart_names_a_written_specific_chart(written: list[Path]) -> None:
    task = next(f for f in written if f.name.endswith(".task.scxml"))
    chart = parse_chart(task.read_bytes(), task)
    named = {s.extra_attrs["{" + PNP_NS + "}chart"] for s in chart.states() if isinstance(s, Parallel)}
    assert named == {f.name for f in written if f.name.startswith("step")}


def test_the_plan_runs_every_step(written: list[Path]) -> None:
    task = next(f for f in written if f.name.endswith(".task.scxml"))
    session = Interpreter(parse_chart(task.read_bytes(), task), clock=ManualClock())
    errors: list[MetaEvent] = []
    session.attach(lambda meta: errors.append(meta) if meta.name == ERROR else None)
    session.start()
    assert [e for e in errors if "data" in e.data["event"].data["message"]] == []  # (sends need devices, not here)
    assert session.datamodel["pnp_plan"] == [1, 2] + [3, 2] * (STEPS // 2 - 1) + [0]  # a body per step, the end


def test_long_task_output_is_small_and_accepted_by_validate(written: list[Path]) -> None:
    assert all(f.stat().st_size <= MAX_BYTES for f in written)
    assert sum(f.stat().st_size for f in written) < STEPS * 1024
    report = validate_paths(written)
    assert report.valid, [str(p) for p in report.sorted()]


@pytest.fixture(scope="module")
def varying_speeds(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Four bin-pick/place cycles that differ only in the place speed."""
    text = (descriptions_path() / "tasks" / "bin-picking.yaml").read_text(encoding="utf-8")
    head, body = text.split("steps:\n")
    steps = "".join(body.replace("speed: 80", f"speed: {speed}") for speed in (20, 40, 60, 80))
    path = tmp_path_factory.mktemp("speeds") / "bin-picking-speeds.yaml"
    path.write_text(head.replace("repeat: 3", "repeat: 1") + "steps:\n" + steps, encoding="utf-8")
    return path


def test_steps_that_differ_only_in_values_share_a_chart_and_the_values_travel_as_data(varying_speeds: Path) -> None:
    cell = service.cell(descriptions_path() / "cells" / "bin-picking.yaml")
    charts = {c.name: c.data for c in service.generate(varying_speeds, cell).charts}
    assert sorted(n for n in charts if n.startswith("step")) == ["step01-bin-pick.scxml", "step02-place.scxml",
                                                                 "step03-bin-pick.scxml"]
    task = parse_chart(charts["bin-picking.task.scxml"], "task")
    values = next(d for d in task.data if d.id == "pnp_values")
    assert [row.get("speed") for row in ast.literal_eval(values.expr or "")] == [None, 20, None, 40, None, 60, None, 80]
    shared = next(s for s in task.states() if s.id == "s2")  # every place step runs it
    params = [p.expr for n in walk(shared) if isinstance(n, Send) for p in n.params]
    assert "pnp_values[pnp_step]['speed']" in params


def test_values_read_from_the_datamodel_run_to_done_in_an_independent_interpreter(varying_speeds: Path) -> None:
    cell = service.cell(descriptions_path() / "cells" / "bin-picking.yaml")
    world = next(c for c in service.generate(varying_speeds, cell).charts if c.kind == "closed-world")
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", world.data.decode())
    assert set(processor.start().configuration_values) == {"done"}


def test_a_shared_specific_chart_carries_the_values_of_its_first_step(varying_speeds: Path) -> None:
    cell = service.cell(descriptions_path() / "cells" / "bin-picking.yaml")
    place = next(c for c in service.generate(varying_speeds, cell).charts if c.name == "step02-place.scxml")
    chart = parse_chart(place.data, place.name)
    assert {d.id: d.expr for d in chart.data} == {"pnp_step": "0", "pnp_values": "[{'speed': 20}]"}
