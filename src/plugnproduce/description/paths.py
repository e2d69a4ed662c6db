"""Path search in a Device State Chart (paper section 6.1).

A General Process State Chart says which state concept a device must reach next; the
Device State Chart says how. The chart is a graph whose edges are its transitions; a
path to any state whose concept is subsumed by the wanted one is searched, shortest by
number of device commands (Dijkstra's, all shortest paths); among equally short paths the one
whose requests accept more of the parameters the step hands over wins (a lift with a
pose moves to it rather than homing), then the one first by state ids, so the result
never depends on dict or set order.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

from plugnproduce.description.model import ChartState, ChartTransition, DeviceDescription
from plugnproduce.errors import PlugNProduceError
from plugnproduce.ontology.taxonomy import Taxonomy


class NoPath(PlugNProduceError):
    """No path in a device's chart from a state to the wanted concept."""

    def __init__(self, device: str, source: str, concept: str):
        self.device, self.source, self.concept = device, source, concept
        super().__init__(f"device {device}: no path in its Device State Chart from state '{source}' to a state of "
                         f"concept {concept.rsplit('#', 1)[-1]}")


@dataclass(frozen=True)
class ChartPath:
    """The transitions taken from ``source`` to ``target`` (empty when already there)."""

    source: str
    target: str
    steps: tuple[ChartTransition, ...]


def commands(t: ChartTransition) -> int:
    """How many device commands a transition carries: its request and the events it sends."""
    return (1 if t.request else 0) + len(t.sends)


Edges = dict[str, dict[str, list[ChartTransition]]]
"""A chart's transitions by source state, then target state."""


def chart_edges(device: DeviceDescription) -> Edges:
    """The Device State Chart as a graph: the transitions from each state to each other, in chart order."""
    out: Edges = {s.id: {} for s in device.states}
    for t in device.transitions:
        out.setdefault(t.source, {}).setdefault(t.target, []).append(t)
        out.setdefault(t.target, {})
    return out


def in_concept(state: ChartState, concept: str, taxonomy: Taxonomy) -> bool:
    """Whether a device in ``state`` is in a state of ``concept``: by the state's own concept or that of a
    compound state around it (``Execute`` inside ``Running``), subsumption counting."""
    return any(taxonomy.is_a(c, concept) for c in state.every_concept)


def matching_states(device: DeviceDescription, concept: str, taxonomy: Taxonomy) -> list[str]:
    """The device's states whose concept the wanted concept subsumes (ClosedWithPart satisfies Closed)."""
    return [s.id for s in device.states if in_concept(s, concept, taxonomy)]


def find_path(
    device: DeviceDescription,
    source: str,
    concept: str,
    taxonomy: Taxonomy,
    wanted: frozenset[str] = frozenset(),
) -> ChartPath:
    """The shortest path from state ``source`` to a state of ``concept`` (empty if ``source`` is one).

    ``wanted`` are the quantities of the parameters handed over on the way.
    """
    goals = matching_states(device, concept, taxonomy)
    if source in goals:
        return ChartPath(source, source, ())
    if not goals:
        raise NoPath(device.id, source, concept)
    edges = chart_edges(device)
    if source not in edges:
        raise NoPath(device.id, source, concept)
    candidates = _shortest(edges, source, set(goals))
    if not candidates:
        raise NoPath(device.id, source, concept)
    ranked = []
    for nodes in candidates:
        steps = tuple(_best_edge(edges, a, b, wanted) for a, b in zip(nodes[:-1], nodes[1:], strict=True))
        accepted = sum(len(wanted.intersection(t.accepts)) for t in steps)
        ranked.append((-accepted, tuple(nodes), tuple(t.line or 0 for t in steps), steps))
    _, best, _, steps = min(ranked)
    return ChartPath(source, best[-1], steps)


def _shortest(edges: Edges, source: str, goals: set[str]) -> list[list[str]]:
    """Every path from ``source`` to a goal state that carries the fewest commands, without a state twice.

    Dijkstra's distances (an edge weighs the fewest commands of the transitions it stands for), then every
    simple path back through the predecessors that keep a distance shortest: the paths networkx's
    ``all_shortest_paths`` gives, without importing networkx (most of a command's start-up)."""
    dist = {source: 0}
    heap = [(0, source)]
    while heap:
        d, a = heapq.heappop(heap)
        if d > dist[a]:
            continue
        for b, ts in edges[a].items():
            nd = d + min(commands(t) for t in ts)
            if nd < dist.get(b, nd + 1):
                dist[b] = nd
                heapq.heappush(heap, (nd, b))
    reached = [g for g in goals if g in dist]
    if not reached:
        return []
    best = min(dist[g] for g in reached)
    pred: dict[str, list[str]] = {}
    for a, targets in edges.items():
        for b, ts in targets.items():
            if a in dist and b in dist and dist[a] + min(commands(t) for t in ts) == dist[b]:
                pred.setdefault(b, []).append(a)
    out: list[list[str]] = []
    for goal in (g for g in reached if dist[g] == best):
        out += _back(pred, source, [goal])
    return out


def _back(pred: dict[str, list[str]], source: str, path: list[str]) -> list[list[str]]:
    """The simple paths from ``source`` that end with ``path`` (reversed), through ``pred``."""
    out = [path[::-1]] if path[-1] == source else []
    for a in pred.get(path[-1], ()):
        if a not in path:
            out += _back(pred, source, [*path, a])
    return out


def _best_edge(edges: Edges, a: str, b: str, wanted: frozenset[str]) -> ChartTransition:
    return min(edges[a][b], key=lambda t: (commands(t), -len(wanted.intersection(t.accepts)), t.line or 0))
