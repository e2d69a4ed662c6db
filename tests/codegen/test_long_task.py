"""Long tasks: identical step charts are generated and written once, and the output stays valid."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.resources import descriptions_path
from plugnproduce.safeio import MAX_BYTES
from plugnproduce.statechart import PNP_NS, Parallel, parse_chart
from plugnproduce.validation.validate import validate_paths

STEPS = 1000
"""Unrolled, this task's closed-world chart was larger than ``pnp validate`` accepts."""


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
    plan = next(d for d in parse_chart(task.read_bytes(), task).data if d.id == "pnp_plan")
    assert plan.expr is not None and plan.expr.count(",") == STEPS  # one body per step, then the end mark


def test_long_task_output_is_small_and_accepted_by_validate(written: list[Path]) -> None:
    assert all(f.stat().st_size <= MAX_BYTES for f in written)
    assert sum(f.stat().st_size for f in written) < STEPS * 1024
    report = validate_paths(written)
    assert report.valid, [str(p) for p in report.sorted()]
