"""The path search gives the paths networkx's all-shortest-paths search gave, without networkx at start-up."""

from __future__ import annotations

import dataclasses
import random

import networkx as nx
import pytest

from plugnproduce import service
from plugnproduce.description.model import ChartState, ChartTransition, Command, DeviceDescription
from plugnproduce.description.paths import ChartPath, NoPath, commands, find_path
from plugnproduce.ontology.taxonomy import Taxonomy

P = "http://plugnproduce.org/ontology#"
LIBRARIES = service.builtin("devices").parents[1] / "tests" / "data" / "libraries"


def networkx_path(device: DeviceDescription, source: str, concept: str, taxonomy: Taxonomy,
                  wanted: frozenset[str] = frozenset()) -> ChartPath:
    """The search as it was written with networkx (a multigraph, a goal node, ``all_shortest_paths``)."""
    goals = [s.id for s in device.states if s.concept and taxonomy.is_a(s.concept, concept)]
    if source in goals:
        return ChartPath(source, source, ())
    g = nx.MultiDiGraph()
    g.add_nodes_from(s.id for s in device.states)
    for i, t in enumerate(device.transitions):
        g.add_edge(t.source, t.target, key=i, transition=t, weight=commands(t))
    for s in goals:
        g.add_edge(s, "\0goal", key=-1, weight=0)
    try:
        candidates = list(nx.all_shortest_paths(g, source, "\0goal", weight="weight"))
    except (nx.NetworkXNoPath, nx.NodeNotFound) as exc:
        raise NoPath(device.id, source, concept) from exc
    ranked = []
    for nodes in candidates:
        steps = tuple(min(g.get_edge_data(a, b).values(),
                          key=lambda e: (e["weight"], -len(wanted.intersection(e["transition"].accepts)),
                                         e["transition"].line or 0))["transition"]
                      for a, b in zip(nodes[:-2], nodes[1:-1], strict=True))
        accepted = sum(len(wanted.intersection(t.accepts)) for t in steps)
        ranked.append((-accepted, tuple(nodes[:-1]), tuple(t.line or 0 for t in steps), steps))
    _, nodes, _, steps = min(ranked)
    return ChartPath(source, nodes[-1], steps)


def same_answer(device: DeviceDescription, source: str, concept: str, taxonomy: Taxonomy,
                wanted: frozenset[str]) -> None:
    try:
        expected: ChartPath | str = networkx_path(device, source, concept, taxonomy, wanted)
    except NoPath as exc:
        expected = str(exc)
    try:
        found: ChartPath | str = find_path(device, source, concept, taxonomy, wanted)
    except NoPath as exc:
        found = str(exc)
    assert found == expected, (device.id, source, concept, wanted)


@pytest.mark.parametrize("library", [None, "machine-tending"])
def test_every_state_to_every_concept_of_the_shipped_and_a_library_catalogue(library: str | None) -> None:
    k = service.knowledge((LIBRARIES / library,) if library else ())
    concepts = sorted({s.concept for d in k.devices for s in d.states if s.concept})
    quantities = sorted({q for d in k.devices for t in d.transitions for q in t.accepts})
    for device in k.devices:
        for state in device.states:
            for concept in concepts:
                for wanted in (frozenset(), frozenset(quantities)):
                    same_answer(device, state.id, concept, k.taxonomy, wanted)


def test_random_charts_with_ties_silent_transitions_and_cycles() -> None:
    """Random charts: parallel transitions, transitions carrying no command (weight 0) and cycles of them, ties
    broken by accepted quantities and lines."""
    k = service.knowledge()
    base = next(d for d in k.devices if d.id == "gripper")
    concepts = [P + "Open", P + "Closed", P + "Moving"]
    rng = random.Random(28)
    for n in range(300):
        ids = [f"s{i}" for i in range(rng.randint(2, 7))]
        states = tuple(ChartState(i, rng.choice([*concepts, None]), None) for i in ids)
        transitions = tuple(ChartTransition(
            rng.choice(ids), rng.choice(ids), rng.choice([None, "xirp.request.Go", "xirp.request.Stop"]),
            tuple(Command("xirp", "event", "e") for _ in range(rng.randint(0, 1))),
            tuple(rng.sample([P + "TargetPose", P + "Speed"], rng.randint(0, 2))), rng.randint(1, 40))
            for _ in range(rng.randint(1, 14)))
        device = dataclasses.replace(base, id=f"random-{n}", states=states, transitions=transitions)
        for source in ids:
            for concept in concepts:
                same_answer(device, source, concept, k.taxonomy, frozenset({P + "TargetPose"}))
