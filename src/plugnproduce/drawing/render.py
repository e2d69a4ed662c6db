"""Graphviz run on a graph: pictures written to files, and the layout's coordinates.

The edge of ``drawing/``: the only module that runs Graphviz. What Graphviz says on its error
stream (warnings about a layout it could not quite make) is logged, never printed.
"""

from __future__ import annotations

import logging
import subprocess
from dataclasses import dataclass
from pathlib import Path

import graphviz

from plugnproduce.drawing.charts import build_graph
from plugnproduce.errors import DescriptionError
from plugnproduce.statechart.io.reader import read_chart
from plugnproduce.statechart.model import Chart

FORMATS = ("svg", "png", "pdf", "dot")
POINTS = 72.0
"""Points per inch: Graphviz lays out in inches."""
log = logging.getLogger(__name__)


def chart_to_dot(chart: Chart | str | Path, name: str | None = None, *, expand: int | None = None) -> graphviz.Digraph:
    """The Graphviz graph of a chart (a model, or an SCXML file read with the one reader).

    ``expand`` names the step of a task chart drawn with its regions (the others stay one box each)."""
    if not isinstance(chart, Chart):
        name = name or Path(chart).stem
        chart = read_chart(chart)
    return build_graph(chart, chart.name or name or "chart", expand)


DOT_TIMEOUT = 120
"""Seconds Graphviz may take for one picture."""


def run_dot(graph: graphviz.Digraph, fmt: str, where: str | Path = "picture") -> bytes:
    """Run Graphviz ``dot`` on ``graph`` into format ``fmt``; its warnings are logged in one line."""
    try:
        done = subprocess.run(["dot", f"-T{fmt}"], input=graph.source.encode("utf-8"), capture_output=True,
                              check=False, timeout=DOT_TIMEOUT)
    except FileNotFoundError as exc:
        raise DescriptionError("Graphviz 'dot' is not installed (scripts/setup.sh installs it)", where) from exc
    except subprocess.TimeoutExpired as exc:
        raise DescriptionError(f"Graphviz took longer than {DOT_TIMEOUT} s to draw the chart", where) from exc
    said = [line for line in done.stderr.decode("utf-8", "replace").splitlines() if line.strip()]
    if done.returncode != 0:
        raise DescriptionError(f"Graphviz could not draw the chart: {said[0] if said else done.returncode}", where)
    if said:
        more = f" (and {len(said) - 1} more)" if len(said) > 1 else ""
        log.info("Graphviz: %s%s", said[0], more)
    picture: bytes = done.stdout
    return picture


def draw_chart(path: str | Path, output: str | Path, *, expand: int | None = None) -> Path:
    """Draw the chart at ``path`` into ``output`` (format from its suffix: .svg, .png, .pdf, .dot)."""
    out = Path(output)
    fmt = out.suffix.lstrip(".").lower()
    if fmt not in FORMATS:
        raise DescriptionError(f"cannot draw to {out.name}; expected a file ending in .svg, .png, .pdf or .dot", out)
    out.write_bytes(render_chart(path, fmt, out, expand=expand))
    return out


def render_chart(chart: Chart | str | Path, fmt: str = "svg", where: str | Path = "picture",
                 name: str | None = None, *, expand: int | None = None) -> bytes:
    """A chart (a model, or an SCXML file) drawn in ``fmt`` (svg, png, pdf or dot), in memory; ``where``
    names the picture in messages; of a task chart, step ``expand`` (from 1) is drawn with its regions."""
    graph = chart_to_dot(chart, name, expand=expand)
    if fmt == "dot":
        return str(graph.source).encode("utf-8")
    return run_dot(graph, fmt, where)


@dataclass(frozen=True)
class Layout:
    """Where Graphviz put a graph's nodes, in points, y growing downwards from the top."""

    width: float
    height: float
    nodes: dict[str, tuple[float, float]]
    """Each node's centre."""


def layout(graph: graphviz.Digraph) -> Layout:
    """Lay ``graph`` out with ``dot`` and read back its size and its nodes' centres."""
    width = height = 0.0
    nodes: dict[str, tuple[float, float]] = {}
    for line in run_dot(graph, "plain").decode("utf-8").splitlines():
        fields = _split(line)
        if fields and fields[0] == "graph":
            width, height = float(fields[2]) * POINTS, float(fields[3]) * POINTS
        elif fields and fields[0] == "node":
            nodes[fields[1]] = (float(fields[2]) * POINTS, height - float(fields[3]) * POINTS)
    return Layout(width, height, nodes)


def _split(line: str) -> list[str]:
    """Fields of a line of ``dot -Tplain`` (names and labels may be quoted)."""
    fields, word, quoted, i = [], "", False, 0
    while i < len(line):
        ch = line[i]
        if quoted and ch == "\\" and i + 1 < len(line):
            word += line[i:i + 2]
            i += 2
            continue
        if ch == '"':
            quoted = not quoted
        elif ch == " " and not quoted:
            fields.append(word)
            word = ""
        else:
            word += ch
        i += 1
    return [*fields, word] if word else fields
