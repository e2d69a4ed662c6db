"""What a description needs from its SCXML chart: concept-annotated states, commands, regions.

Lifts the parts of a chart the descriptions give meaning to (``pnp:concept``,
``pnp:accepts``, ``pnp:role``, ``pnp:params``, protocol-prefixed events), with their
lines. The chart is parsed with the hardened parser; schema validity is checked
separately (:mod:`plugnproduce.statechart.schema`).
"""

from __future__ import annotations

import re
from pathlib import Path

from lxml import etree

from plugnproduce.description.model import ChartState, ChartTransition, Command, RegionState
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.vocabulary import PNP_IRI, concept_iri
from plugnproduce.safeio import excerpt, parse_xml

SCXML = "{http://www.w3.org/2005/07/scxml}"
CONCEPT = "{" + PNP_IRI + "}concept"
ACCEPTS = "{" + PNP_IRI + "}accepts"
ROLE = "{" + PNP_IRI + "}role"
PARAMS = "{" + PNP_IRI + "}params"
_IN = re.compile(r"""In\(\s*['"]([^'"]+)['"]\s*\)""")
_STATES = (SCXML + "state", SCXML + "final")


def _root(path: str | Path) -> etree._Element:
    root = parse_xml(path).getroot()
    if root.tag != SCXML + "scxml":
        raise DescriptionError(f"expected an <scxml> document in the SCXML namespace; found <{excerpt(root.tag)}>",
                               path, root.sourceline)
    return root


def _sends(parent: etree._Element | None) -> list[Command]:
    out: list[Command] = []
    if parent is None:
        return out
    for send in parent.iter(SCXML + "send"):
        cmd = Command.parse(send.get("event", ""))
        if cmd is not None and cmd.kind == "event":
            out.append(cmd)
    return out


def _concept(el: etree._Element) -> str | None:
    value = el.get(CONCEPT)
    return concept_iri(value) if value else None


def device_chart(path: str | Path) -> tuple[str, tuple[ChartState, ...], tuple[ChartTransition, ...]]:
    """The initial state, states and transitions of a (flat) Device State Chart."""
    root = _root(path)
    states = [c for c in root if c.tag in _STATES]
    for c in root:
        if c.tag in (SCXML + "parallel",) or (c.tag == SCXML + "state" and c.find(SCXML + "state") is not None):
            raise DescriptionError("a Device State Chart must be flat: found a compound or parallel state; "
                                   "expected only <state> and <final> at the top", path, c.sourceline)
    initial = (root.get("initial") or (states[0].get("id", "") if states else "")).split()[0] if states else ""
    entry = {s.get("id"): _sends(s.find(SCXML + "onentry")) for s in states}
    chart_states = tuple(ChartState(s.get("id", ""), _concept(s), s.sourceline) for s in states)
    transitions: list[ChartTransition] = []
    for s in states:
        for t in s.findall(SCXML + "transition"):
            for target in (t.get("target") or s.get("id", "")).split():
                sends = tuple(_sends(t)) + tuple(entry.get(target, ()))
                accepts = tuple(concept_iri(a) for a in (t.get(ACCEPTS) or "").split())
                transitions.append(ChartTransition(s.get("id", ""), target, t.get("event"), sends, accepts,
                                                   t.sourceline))
    return initial, chart_states, tuple(transitions)


def process_regions(path: str | Path) -> dict[str, tuple[RegionState, ...]]:
    """Role name → its region's states in visiting order, from a General Process State Chart."""
    root = _root(path)
    parallels = root.findall(SCXML + "parallel")
    if len(parallels) != 1:
        raise DescriptionError(
            f"a General Process State Chart has one top-level <parallel>; found {len(parallels)}", path,
            root.sourceline)
    regions: dict[str, tuple[RegionState, ...]] = {}
    for region in parallels[0]:
        if not isinstance(region.tag, str) or not region.tag.startswith(SCXML):
            continue
        role = region.get(ROLE)
        if region.tag != SCXML + "state" or not role:
            raise DescriptionError("each region of the <parallel> must be a <state> with a pnp:role attribute",
                                   path, region.sourceline)
        regions[role] = _region_sequence(region, path)
    return regions


def _region_sequence(region: etree._Element, path: str | Path) -> tuple[RegionState, ...]:
    children = [c for c in region if c.tag in _STATES]
    by_id = {c.get("id"): c for c in children}
    first = region.get("initial")
    current = by_id.get(first.split()[0]) if first else (children[0] if children else None)
    seq: list[RegionState] = []
    params: tuple[str, ...] = ()
    waits: str | None = None
    name = region.get("id")
    while current is not None:
        sid = current.get("id", "")
        if any(s.id == sid for s in seq):
            raise DescriptionError(f"region {name!r} loops back to {sid!r}; expected a sequence", path,
                                   current.sourceline)
        concept = _concept(current)
        if concept is None:
            raise DescriptionError(f"state {sid!r} has no pnp:concept; expected a state concept", path,
                                   current.sourceline)
        seq.append(RegionState(sid, concept, current.sourceline, params, waits))
        transitions = current.findall(SCXML + "transition")
        if current.tag == SCXML + "final" or not transitions:
            break
        if len(transitions) != 1 or len((transitions[0].get("target") or "").split()) != 1:
            raise DescriptionError(f"state {sid!r} must have exactly one transition with one target", path,
                                   current.sourceline)
        t = transitions[0]
        params = tuple((t.get(PARAMS) or "").split())
        m = _IN.search(t.get("cond") or "")
        waits = m.group(1) if m else None
        current = by_id.get(t.get("target"))
        if current is None:
            raise DescriptionError(f"transition leaves region {name!r}", path, t.sourceline)
    if not seq or by_id[seq[-1].id].tag != SCXML + "final":
        raise DescriptionError(f"region {name!r} must end in a <final> state", path, region.sourceline)
    return tuple(seq)
