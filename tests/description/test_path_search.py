"""The path search gives the paths networkx's all-shortest-paths search gave, without networkx at start-up; and a
parameter is not dropped while the chart can take it (an Open → Open region goes through the request taking it)."""

from __future__ import annotations

import dataclasses
import itertools
import random

import networkx as nx
import pytest

from plugnproduce import service
from plugnproduce.description.model import ChartState, ChartTransition, Command, DeviceDescription
from plugnproduce.description.paths import ChartPath, NoPath, commands, find_path
from plugnproduce.ontology.taxonomy import Taxonomy

P = "http://plugnproduce.org/ontology#"
LIBRARIES = service.builtin("devices").parents[1] / "tests" / "data" / "libraries"


def taken(steps: tuple[ChartTransition, ...], wanted: frozenset[str]) -> frozenset[str]:
    return frozenset(q for t in steps if t.request for q in t.accepts if q in wanted)


def networkx_path(device: DeviceDescription, source: str, concept: str, taxonomy: Taxonomy,
                  wanted: frozenset[str] = frozenset()) -> ChartPath:
    """The shortest path; but when another path, each of whose requests takes some of ``wanted``, takes more of
    ``wanted``, the shortest of those taking the most (a parameter is not dropped while the chart can take it)."""
    shortest = networkx_shortest(device, source, concept, taxonomy, wanted)
    takeable = taken(device.transitions, wanted)
    if takeable <= taken(shortest.steps, wanted):
        return shortest
    g = nx.MultiDiGraph()  # (state, what is taken so far), every pair there is
    for state in device.states:
        for n in range(len(takeable) + 1):
            for part in itertools.combinations(sorted(takeable), n):
                for i, t in enumerate(device.transitions):
                    if t.source == state.id and (not t.request or taken((t,), wanted)):
                        g.add_edge((state.id, frozenset(part)), (t.target, frozenset(part) | taken((t,), wanted)),
                                   key=i, transition=t, weight=commands(t))
    goals = [s.id for s in device.states if s.concept and taxonomy.is_a(s.concept, concept)]
    for count in range(len(takeable), len(taken(shortest.steps, wanted)), -1):
        ends = [n for n in g.nodes if n[0] in goals and len(n[1]) == count]
        h = g.copy()
        h.add_edges_from((n, "\0goal", -1, {"weight": 0}) for n in ends)
        try:
            candidates = list(nx.all_shortest_paths(h, (source, frozenset()), "\0goal", weight="weight"))
        except (nx.NetworkXNoPath, nx.NodeNotFound):
            continue
        ranked = []
        for nodes in candidates:
            steps = tuple(min(h.get_edge_data(a, b).values(),
                              key=lambda e: (e["weight"], -len(wanted.intersection(e["transition"].accepts)),
                                             e["transition"].line or 0))["transition"]
                          for a, b in zip(nodes[:-2], nodes[1:-1], strict=True))
            ranked.append((tuple(n[0] for n in nodes[:-1]), tuple(t.line or 0 for t in steps), steps))
        states, _, steps = min(ranked)
        return ChartPath(source, states[-1], steps)
    return shortest


def networkx_shortest(device: DeviceDescription, source: str, concept: str, taxonomy: Taxonomy,
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


def test_issue_27_open_to_open_handing_over_an_angle_goes_through_the_request_taking_it() -> None:
    k = service.knowledge()
    gripper = next(d for d in k.devices if d.id == "gripper")
    stay = find_path(gripper, "open", P + "Open", k.taxonomy)
    assert stay.steps == ()
    angle = find_path(gripper, "open", P + "Open", k.taxonomy, frozenset({P + "OpeningAngle"}))
    assert [(t.source, t.request.name if t.request else None, t.target) for t in angle.steps] == [
        ("open", "SetAngle", "configuring"), ("configuring", None, "open")]
    deaf = find_path(gripper, "open", P + "Open", k.taxonomy, frozenset({P + "TargetPose"}))
    assert deaf.steps == ()  # nothing in the gripper's chart takes a pose: it stays open


def test_issue_27_no_other_request_is_sent_on_the_way_to_the_one_taking_the_angle() -> None:
    """A gripper that takes its angle only when closed: closing it on the way would move it where the step says
    it stays open; the route stays put (and the check says the value would be lost)."""
    k = service.knowledge()
    gripper = next(d for d in k.devices if d.id == "gripper")
    moved = tuple(dataclasses.replace(t, source="closed") if t.request and t.request.name == "SetAngle" else t
                  for t in gripper.transitions)
    closed_only = dataclasses.replace(gripper, transitions=moved)
    assert find_path(closed_only, "open", P + "Open", k.taxonomy, frozenset({P + "OpeningAngle"})).steps == ()
