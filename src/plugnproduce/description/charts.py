"""What a description needs from its SCXML chart: concept-annotated states, commands, regions.

Lifts the parts of a chart the descriptions give meaning to (``pnp:concept``,
``pnp:accepts``, ``pnp:role``, ``pnp:params``, protocol-prefixed events), with their
lines, from a chart the one SCXML reader (:mod:`plugnproduce.statechart.io.reader`)
has parsed. Schema validity is checked separately (:mod:`plugnproduce.statechart.io.schema`).
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

from plugnproduce.description.hierarchy import DeviceChart as DeviceChart
from plugnproduce.description.hierarchy import device_chart as device_chart
from plugnproduce.description.model import RegionState
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.iris import concept_iri
from plugnproduce.statechart.model import (
    CONCEPT,
    Chart,
    Final,
    Node,
    Parallel,
    State,
    StateNode,
    Transition,
    pnp,
)

ACCEPTS, ROLE, PARAMS, OUTCOMES = pnp("accepts"), pnp("role"), pnp("params"), pnp("outcomes")
_IN = re.compile(r"""In\(\s*['"]([^'"]+)['"]\s*\)""")


def _concept(node: Node) -> str | None:
    value = node.extra_attrs.get(CONCEPT)
    return concept_iri(value) if value else None


def process_regions(chart: Chart, path: str | Path) -> dict[str, tuple[RegionState, ...]]:
    """Role name → its region's states in visiting order, from a General Process State Chart."""
    parallels = [c for c in chart.children if isinstance(c, Parallel)]
    if len(parallels) != 1:
        raise DescriptionError(
            f"a General Process State Chart has one top-level <parallel>; found {len(parallels)}", path, chart.line)
    regions: dict[str, tuple[RegionState, ...]] = {}
    for region in parallels[0].children:
        role = region.extra_attrs.get(ROLE)
        if not isinstance(region, State) or not role:
            raise DescriptionError("each region of the <parallel> must be a <state> with a pnp:role attribute",
                                   path, region.line)
        regions[role] = _region_sequence(region, path)
    return regions


def _region_sequence(region: State, path: str | Path) -> tuple[RegionState, ...]:
    children = [c for c in region.children if isinstance(c, State | Final)]
    by_id: dict[str | None, State | Final] = {c.id: c for c in children}
    current = by_id.get(region.initial[0]) if region.initial else (children[0] if children else None)
    seq: list[RegionState] = []
    params: tuple[str, ...] = ()
    waits: str | None = None
    while current is not None:
        sid = current.id or ""
        if any(s.id == sid for s in seq):
            raise DescriptionError(f"region {region.id!r} loops back to {sid!r}; expected a sequence", path,
                                   current.line)
        concept = _concept(current)
        if concept is None:
            raise DescriptionError(f"state {sid!r} has no pnp:concept; expected a state concept", path, current.line)
        seq.append(RegionState(sid, concept, current.line, params, waits))
        transitions = current.transitions if isinstance(current, State) else []
        if isinstance(current, Final) or not transitions:
            break
        t = _only_transition(current, transitions, path)
        params = tuple(t.extra_attrs.get(PARAMS, "").split())
        m = _IN.search(t.cond or "")
        waits = m.group(1) if m else None
        current = by_id.get(t.targets[0])
        if current is None:
            raise DescriptionError(f"transition leaves region {region.id!r}", path, t.line)
    if not seq or not isinstance(by_id[seq[-1].id], Final):
        raise DescriptionError(f"region {region.id!r} must end in a <final> state", path, region.line)
    final = by_id[seq[-1].id]
    outcomes = tuple(concept_iri(o) for o in final.extra_attrs.get(OUTCOMES, "").split())
    seq[-1] = dataclasses.replace(seq[-1], outcomes=outcomes)
    return tuple(seq)


def _only_transition(state: StateNode, transitions: list[Transition], path: str | Path) -> Transition:
    if len(transitions) != 1 or len(transitions[0].targets) != 1:
        raise DescriptionError(f"state {state.id!r} must have exactly one transition with one target", path,
                               state.line)
    return transitions[0]
