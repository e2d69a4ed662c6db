"""Pictures of state charts: device, process and task charts drawn with Graphviz.

Compound and parallel states become clusters (a parallel's regions side by side),
atomic states become nodes labelled with their id and ontology concept, and every
transition an edge labelled ``event [cond] / commands``.
"""

from __future__ import annotations

from pathlib import Path

import graphviz

from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.vocabulary import PNP_IRI, local_name
from plugnproduce.statechart.io.reader import read_chart
from plugnproduce.statechart.model import Chart, Final, Parallel, Raise, Send, State, StateNode, Transition, walk

FORMATS = ("svg", "png", "pdf", "dot")
_Edge = tuple[str, str, str, "str | None"]


def _is_compound(node: StateNode) -> bool:
    return isinstance(node, Parallel) or (isinstance(node, State) and bool(node.children))


def _anchor(node: StateNode) -> str:
    """The node an edge to ``node`` points at: itself, or its first atomic descendant."""
    while isinstance(node, State | Parallel) and node.children:
        node = node.children[0]
    return node.id or ""


def _label(t: Transition) -> str:
    parts = []
    if t.event:
        parts.append(t.event)
    if t.cond:
        parts.append(f"[{t.cond}]")
    actions = []
    for a in (n for action in t.actions for n in walk(action, into_charts=False)):
        if isinstance(a, Send | Raise):
            verb = "send" if isinstance(a, Send) else "raise"
            target = f" → {a.target}" if isinstance(a, Send) and a.target else ""
            actions.append(f"{verb} {a.event or ''}{target}")
    if actions:
        parts.append("/ " + "\\n".join(actions))
    return "\\n".join(parts)


def _state_label(node: StateNode) -> str:
    concept = node.extra_attrs.get("{" + PNP_IRI + "}concept")
    return f"{node.id}\\n«{local_name(concept)}»" if concept else str(node.id)


def _add(graph: graphviz.Digraph, container: Chart | State | Parallel, edges: list[_Edge]) -> None:
    for child in container.children:
        if not isinstance(child, State | Parallel | Final):
            continue
        sid = child.id or ""
        if _is_compound(child):
            with graph.subgraph(name=f"cluster_{sid}") as sub:
                style = "dashed" if isinstance(child, Parallel) else "rounded"
                role = child.extra_attrs.get("{" + PNP_IRI + "}role")
                sub.attr(label=f"{sid}" + (f" (role {role})" if role else ""), style=style)
                _add(sub, child, edges)  # type: ignore[arg-type]
        else:
            final = "2" if isinstance(child, Final) else "1"
            graph.node(sid, _state_label(child), shape="box", style="rounded", peripheries=final)
        for t in child.transitions if isinstance(child, State | Parallel) else ():
            for target in t.targets:
                edges.append((sid, target, _label(t), f"cluster_{sid}" if _is_compound(child) else None))


def chart_to_dot(chart: Chart | str | Path, name: str | None = None) -> graphviz.Digraph:
    """The Graphviz graph of a chart (a model, or an SCXML file read with the one reader)."""
    if not isinstance(chart, Chart):
        name = name or Path(chart).stem
        chart = read_chart(chart)
    title = chart.name or name or "chart"
    graph = graphviz.Digraph(name=title)
    graph.attr(rankdir="LR", compound="true", fontname="Helvetica", label=title)
    graph.attr("node", fontname="Helvetica", fontsize="10")
    graph.attr("edge", fontname="Helvetica", fontsize="8")
    edges: list[_Edge] = []
    _add(graph, chart, edges)
    ids = {node.id: node for node in chart.states() if node.id}
    for source, target, label, ltail in edges:
        if target not in ids:
            continue
        attrs = {"label": label}
        src = _anchor(ids[source]) if source in ids else source
        if ltail:
            attrs["ltail"] = ltail
        if _is_compound(ids[target]):
            attrs["lhead"] = f"cluster_{target}"
        graph.edge(src, _anchor(ids[target]), **attrs)
    return graph


def draw_chart(path: str | Path, output: str | Path) -> Path:
    """Draw the chart at ``path`` into ``output`` (format from its suffix: .svg, .png, .pdf, .dot)."""
    out = Path(output)
    fmt = out.suffix.lstrip(".").lower()
    if fmt not in FORMATS:
        raise DescriptionError(f"cannot draw to {out.name}; expected a file ending in .svg, .png, .pdf or .dot", out)
    out.write_bytes(render_chart(path, fmt, out))
    return out


def render_chart(chart: Chart | str | Path, fmt: str = "svg", where: str | Path = "picture",
                 name: str | None = None) -> bytes:
    """A chart (a model, or an SCXML file) drawn in ``fmt`` (svg, png, pdf or dot), in memory;
    ``where`` names the picture in messages."""
    graph = chart_to_dot(chart, name)
    if fmt == "dot":
        return str(graph.source).encode("utf-8")
    try:
        data: bytes = graph.pipe(format=fmt)
    except graphviz.ExecutableNotFound as exc:
        raise DescriptionError("Graphviz 'dot' is not installed (scripts/setup.sh installs it)", where) from exc
    return data
