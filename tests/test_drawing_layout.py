"""The layout of generated charts' pictures, read from Graphviz's own coordinates: steps in order,
pictures of a bounded size however long the task."""

from __future__ import annotations

import logging
from pathlib import Path

import graphviz
import pytest

from plugnproduce import service
from plugnproduce.drawing import SHOWN, Layout, chart_to_dot, column_length, layout, run_dot, shown_steps, step_node
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.model import Chart, Data, Final, State, StateNode, Transition

D = descriptions_path()
BOUND = {6: (600.0, 1000.0), 100: (2000.0, 2000.0)}
"""Steps → the largest (width, height) in points a task's picture may take."""


def _charts(steps: int, tmp_path: Path) -> dict[str, bytes]:
    text = (D / "tasks" / "bin-picking.yaml").read_text(encoding="utf-8")
    task = tmp_path / "task.yaml"
    task.write_text(text.replace("repeat: 3", f"repeat: {steps // 2}"), encoding="utf-8")
    generated = service.generate(task, D / "cells" / "bin-picking.yaml", per_device=True)
    return {c.kind if c.kind != "device-program" else c.name: c.data for c in generated.charts}


@pytest.fixture(scope="module", params=[6, 100], ids=lambda n: f"{n}-steps")
def task_layout(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> tuple[int, Layout]:
    steps: int = request.param
    charts = _charts(steps, tmp_path_factory.mktemp("gen"))
    return steps, layout(chart_to_dot(parse_chart(charts["task"], "task.scxml")))


def test_steps_go_down_a_column_in_order(task_layout: tuple[int, Layout]) -> None:
    steps, drawn = task_layout
    k = column_length(steps)
    for first in range(1, steps + 1, k):
        column = [drawn.nodes[step_node(n)] for n in range(first, min(first + k, steps + 1))]
        ys = [y for _, y in column]
        assert ys == sorted(ys) and len(set(ys)) == len(ys), f"steps {first}… not top to bottom: {ys}"


def test_columns_follow_each_other_left_to_right(task_layout: tuple[int, Layout]) -> None:
    steps, drawn = task_layout
    k = column_length(steps)
    tops = [drawn.nodes[step_node(n)][0] for n in range(1, steps + 1, k)]
    lasts = [drawn.nodes[step_node(min(n + k - 1, steps))][0] for n in range(1, steps + 1, k)]
    assert all(a < b for a, b in zip(lasts[:-1], tops[1:], strict=True)), f"columns out of order: {tops}"


def test_the_picture_stays_within_its_bound(task_layout: tuple[int, Layout]) -> None:
    steps, drawn = task_layout
    width, height = BOUND[steps]
    assert drawn.width <= width and drawn.height <= height, f"{drawn.width:.0f} × {drawn.height:.0f} pt"


def test_closed_world_and_device_programs_stay_small(tmp_path: Path) -> None:
    charts = _charts(6, tmp_path)
    sizes = {name: layout(chart_to_dot(parse_chart(data, name))) for name, data in charts.items()
             if name != "specific"}
    programs = [d for name, d in sizes.items() if name.endswith(".program.scxml")]
    assert programs and all(d.width <= 800 and d.height <= 800 for d in programs)
    cw = sizes["closed-world"]
    assert cw.width * cw.height <= 2400 * 900
    steps = [cw.nodes[step_node(n)][1] for n in range(1, 7)]
    assert steps == sorted(steps)


def test_an_expanded_step_shows_its_regions_and_the_others_stay_boxes(tmp_path: Path) -> None:
    chart = parse_chart(_charts(6, tmp_path)["task"], "task.scxml")
    source = chart_to_dot(chart, expand=3).source
    assert f"cluster_{step_node(3)}" in source and "s3_robot_idle" in source
    assert all(f"\t{step_node(n)} [" in source for n in (1, 2, 4, 5, 6))
    assert f"\t{step_node(3)} [" not in source and "s1_robot_idle" not in source
    assert source.count("subgraph cluster_s3_robot ") == 1 and source.count("s3_robot_idle -> s3_robot_approach") == 1
    drawn = layout(chart_to_dot(chart, expand=3))
    ys = [drawn.nodes[step_node(2)][1], drawn.nodes["s3_robot_idle"][1], drawn.nodes[step_node(4)][1]]
    assert ys == sorted(ys)


def test_graphviz_warnings_are_logged_not_printed(capfd: pytest.CaptureFixture[str],
                                                  caplog: pytest.LogCaptureFixture) -> None:
    graph = graphviz.Digraph()
    graph.attr(compound="true")
    graph.edge("a", "b", lhead="cluster_nowhere")
    with caplog.at_level(logging.INFO, logger="plugnproduce.drawing"):
        assert run_dot(graph, "svg").startswith(b"<?xml")
    assert capfd.readouterr().err == ""
    assert len(caplog.records) == 1 and "Graphviz" in caplog.records[0].getMessage()


def _program(segments: int) -> Chart:
    """A device program of ``segments`` distinct three-state segments, each run once."""
    plan = ", ".join(str(k) for k in range(1, segments + 1))
    picker = State(id="next_step", transitions=[
        *(Transition(cond=f"pnp_plan[pnp_step] == {k}", targets=[f"q{k}_0"]) for k in range(1, segments + 1)),
        Transition(cond="pnp_plan[pnp_step] == 0", targets=["end"])])
    states: list[StateNode] = [State(id="p0", transitions=[Transition(targets=["next_step"])]), picker]
    for k in range(1, segments + 1):
        states += [State(id=f"q{k}_0", transitions=[Transition(event="xirp.request.Open", targets=[f"q{k}_1"])]),
                   State(id=f"q{k}_1", transitions=[Transition(event="done", targets=[f"q{k}_2"])]),
                   State(id=f"q{k}_2", transitions=[Transition(targets=["next_step"])])]
    return Chart(name="gripper-program", initial=["p0"], children=[*states, Final(id="end")],
                 data=[Data(id="pnp_plan", expr=f"[{plan}, 0]"), Data(id="pnp_step", expr="0")])


def test_a_device_program_s_many_segments_fold_into_rows_in_order() -> None:
    drawn = layout(chart_to_dot(_program(40)))
    row = 7  # segments to a row: about as many as rows
    firsts = [drawn.nodes[f"q{k}_0"] for k in range(1, 41)]
    for start in range(0, 40, row):
        xs = [x for x, _ in firsts[start:start + row]]
        assert xs == sorted(xs), f"segments {start + 1}… not left to right"
    tops = [firsts[start][1] for start in range(0, 40, row)]
    assert tops == sorted(tops) and len(set(tops)) == len(tops), "rows not top to bottom"
    assert drawn.width <= 2000 and drawn.height <= 2000, f"{drawn.width:.0f} × {drawn.height:.0f} pt"


def test_a_long_task_draws_the_steps_around_the_expanded_one(tmp_path: Path) -> None:
    chart = parse_chart(_charts(1000, tmp_path)["task"], "task.scxml")
    first, last = shown_steps(1000, 700)
    assert (first, last) == (600, 799) and last - first + 1 == SHOWN
    drawn = layout(chart_to_dot(chart, expand=700))
    steps = [n for n in drawn.nodes if n.startswith("pnp_step_")]
    assert step_node(599) not in steps and step_node(800) not in steps and step_node(600) in steps
    assert {"pnp_steps_before", "pnp_steps_after"} <= set(drawn.nodes)
    assert drawn.width <= 5000 and drawn.height <= 5000, f"{drawn.width:.0f} × {drawn.height:.0f} pt"
