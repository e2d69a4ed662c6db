"""``pnp draw``: what Graphviz says while laying out stays off the terminal; ``--step`` expands a step."""

from __future__ import annotations

from pathlib import Path

import graphviz
import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.drawing import render

runner = CliRunner()


def _warning_graph(*_: object, **__: object) -> graphviz.Digraph:
    """A graph Graphviz warns about (an edge to a cluster that is not there)."""
    graph = graphviz.Digraph()
    graph.attr(compound="true")
    graph.edge("a", "b", lhead="cluster_nowhere")
    return graph


def test_a_graphviz_warning_does_not_reach_the_terminal(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                         capfd: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(render, "chart_to_dot", _warning_graph)
    result = runner.invoke(app, ["draw", str(service.builtin("devices", "gripper.scxml")), "-o",
                                 str(tmp_path / "g.svg")])
    assert result.exit_code == 0 and result.output == f"wrote {tmp_path / 'g.svg'}\n"
    assert capfd.readouterr().err == ""


def test_draw_expands_the_step_asked_for(tmp_path: Path) -> None:
    out = tmp_path / "gen"
    out.mkdir()
    for chart in service.generate(service.builtin("tasks", "bin-picking.yaml"),
                                  service.builtin("cells", "bin-picking.yaml")).charts:
        (out / chart.name).write_bytes(chart.data)
    result = runner.invoke(app, ["draw", str(out / "bin-picking.task.scxml"), "--step", "2", "-o",
                                 str(tmp_path / "t.dot")])
    assert result.exit_code == 0, result.output
    dot = (tmp_path / "t.dot").read_text(encoding="utf-8")
    assert "cluster_pnp_step_2" in dot and "\tpnp_step_1 [" in dot
