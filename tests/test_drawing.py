"""Pictures of device, process and task charts."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.drawing import chart_to_dot, draw_chart
from plugnproduce.errors import DescriptionError
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import Chart, State, Transition

D = descriptions_path()


def test_device_chart_shows_states_concepts_and_commands() -> None:
    dot = chart_to_dot(D / "devices" / "gripper.scxml").source
    assert 'closed\\n«Closed»' in dot
    assert "xirp.request.Open" in dot
    assert "send xirp.event.gripper_closed" in dot


def test_process_chart_draws_each_role_as_a_cluster() -> None:
    dot = chart_to_dot(D / "processes" / "pick.scxml").source
    assert "subgraph cluster_robot" in dot and "subgraph cluster_gripper" in dot
    assert "role gripper" in dot
    assert "In('robot_at_part')" in dot


@pytest.mark.parametrize("suffix", ["svg", "png"])
def test_draw_writes_a_picture(tmp_path: Path, suffix: str) -> None:
    out = draw_chart(D / "processes" / "bin-pick.scxml", tmp_path / f"bin-pick.{suffix}")
    data = out.read_bytes()
    assert data.startswith(b"\x89PNG") if suffix == "png" else b"<svg" in data


def test_unknown_picture_format_is_refused(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match="expected a file ending in .svg"):
        draw_chart(D / "devices" / "gripper.scxml", tmp_path / "x.gif")


def test_a_chart_model_is_drawn_without_a_file() -> None:
    chart = Chart(name="toggle", initial=["off"], children=[
        State(id="off", transitions=[Transition(event="flip", targets=["on"])]),
        State(id="on", transitions=[Transition(event="flip", targets=["off"])])])
    dot = chart_to_dot(chart).source
    assert "digraph toggle" in dot and "off -> on" in dot and "flip" in dot
