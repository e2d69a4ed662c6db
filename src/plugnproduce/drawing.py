"""Pictures of state charts: device, process and task charts drawn with Graphviz.

Compound and parallel states become clusters (a parallel's regions side by side),
atomic states become nodes labelled with their id and ontology concept, and every
transition an edge labelled ``event [cond] / commands``.
"""

from __future__ import annotations

from pathlib import Path

import graphviz
from lxml import etree

from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.vocabulary import PNP_IRI, local_name
from plugnproduce.safeio import parse_xml

SCXML = "{http://www.w3.org/2005/07/scxml}"
_CONTAINERS = {SCXML + "state", SCXML + "parallel", SCXML + "final", SCXML + "history", SCXML + "initial"}
FORMATS = ("svg", "png", "pdf", "dot")


def _is_compound(el: etree._Element) -> bool:
    return el.tag == SCXML + "parallel" or any(c.tag in _CONTAINERS for c in el)


def _anchor(el: etree._Element) -> str:
    """The node an edge to ``el`` points at: itself, or its first atomic descendant."""
    while _is_compound(el):
        el = next(c for c in el if c.tag in _CONTAINERS and c.tag != SCXML + "initial")
    anchor: str = el.get("id", "")
    return anchor


def _label(t: etree._Element) -> str:
    parts = []
    if t.get("event"):
        parts.append(t.get("event", ""))
    if t.get("cond"):
        parts.append(f"[{t.get('cond')}]")
    actions = []
    for a in t.iter(SCXML + "send", SCXML + "raise"):
        verb = "send" if a.tag == SCXML + "send" else "raise"
        target = f" → {a.get('target')}" if a.get("target") else ""
        actions.append(f"{verb} {a.get('event', '')}{target}")
    if actions:
        parts.append("/ " + "\\n".join(actions))
    return "\\n".join(parts)


def _state_label(el: etree._Element) -> str:
    concept = el.get("{" + PNP_IRI + "}concept")
    return f"{el.get('id')}\\n«{local_name(concept)}»" if concept else str(el.get("id"))


def _add(graph: graphviz.Digraph, el: etree._Element, edges: list[tuple[str, str, str, str | None]]) -> None:
    for child in el:
        if child.tag not in _CONTAINERS or child.tag == SCXML + "initial":
            continue
        sid = child.get("id", "")
        if _is_compound(child):
            with graph.subgraph(name=f"cluster_{sid}") as sub:
                style = "dashed" if child.tag == SCXML + "parallel" else "rounded"
                role = child.get("{" + PNP_IRI + "}role")
                sub.attr(label=f"{sid}" + (f" (role {role})" if role else ""), style=style)
                _add(sub, child, edges)
        else:
            final = "2" if child.tag == SCXML + "final" else "1"
            graph.node(sid, _state_label(child), shape="box", style="rounded", peripheries=final)
        for t in child.findall(SCXML + "transition"):
            for target in (t.get("target") or "").split():
                edges.append((sid, target, _label(t), f"cluster_{sid}" if _is_compound(child) else None))


def chart_to_dot(path: str | Path) -> graphviz.Digraph:
    """The Graphviz graph of an SCXML chart."""
    root = parse_xml(path).getroot()
    if root.tag != SCXML + "scxml":
        raise DescriptionError("expected an <scxml> document", path, root.sourceline)
    graph = graphviz.Digraph(name=root.get("name") or Path(path).stem)
    graph.attr(rankdir="LR", compound="true", fontname="Helvetica", label=root.get("name") or Path(path).stem)
    graph.attr("node", fontname="Helvetica", fontsize="10")
    graph.attr("edge", fontname="Helvetica", fontsize="8")
    edges: list[tuple[str, str, str, str | None]] = []
    _add(graph, root, edges)
    ids = {el.get("id"): el for el in root.iter() if el.get("id")}
    for source, target, label, ltail in edges:
        if target not in ids:
            continue
        attrs = {"label": label}
        src_el = ids.get(source)
        src = _anchor(src_el) if src_el is not None else source
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
    graph = chart_to_dot(path)
    if fmt == "dot":
        out.write_text(graph.source)
        return out
    try:
        data = graph.pipe(format=fmt)
    except graphviz.ExecutableNotFound as exc:
        raise DescriptionError("Graphviz 'dot' is not installed (scripts/setup.sh installs it)", out) from exc
    out.write_bytes(data)
    return out
