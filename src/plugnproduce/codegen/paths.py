"""Path search in a Device State Chart (paper section 6.1).

A General Process State Chart says which state concept a device must reach next; the
Device State Chart says how. The chart becomes a multigraph whose edges are its
transitions; a path to any state whose concept is subsumed by the wanted one is
searched, shortest by number of device commands; among equally short paths the one
whose requests accept more of the parameters the step hands over wins (a lift with a
pose moves to it rather than homing), then the one first by state ids, so the result
never depends on dict or set order.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.ontology.taxonomy import Taxonomy


class NoPath(Exception):
    """No path in a device's chart from a state to the wanted concept."""

    def __init__(self, device: str, source: str, concept: str):
        self.device, self.source, self.concept = device, source, concept
        super().__init__(f"device {device}: no path in its Device State Chart from state '{source}' to a state of "
                         f"concept {concept.rsplit('#', 1)[-1]}")


@dataclass(frozen=True)
class Path:
    """The transitions taken from ``source`` to ``target`` (empty when already there)."""

    source: str
    target: str
    steps: tuple[ChartTransition, ...]


def commands(t: ChartTransition) -> int:
    """How many device commands a transition carries: its request and the events it sends."""
    return (1 if t.request else 0) + len(t.sends)


def chart_graph(device: DeviceDescription) -> dict[str, dict[str, list[ChartTransition]]]:
    """The Device State Chart as a graph: for each state, its successors and the transitions to each."""
    g: dict[str, dict[str, list[ChartTransition]]] = {s.id: {} for s in device.states}
    for t in device.transitions:
        g.setdefault(t.source, {}).setdefault(t.target, []).append(t)
    return g


def matching_states(device: DeviceDescription, concept: str, taxonomy: Taxonomy) -> list[str]:
    """The device's states whose concept the wanted concept subsumes (ClosedWithPart satisfies Closed)."""
    return [s.id for s in device.states if s.concept and taxonomy.is_a(s.concept, concept)]


def find_path(
    device: DeviceDescription,
    source: str,
    concept: str,
    taxonomy: Taxonomy,
    wanted: frozenset[str] = frozenset(),
) -> Path:
    """The shortest path from state ``source`` to a state of ``concept`` (empty if ``source`` is one).

    ``wanted`` are the quantities of the parameters handed over on the way.
    """
    goals = matching_states(device, concept, taxonomy)
    if source in goals:
        return Path(source, source, ())
    if not goals:
        raise NoPath(device.id, source, concept)
    g = chart_graph(device)
    candidates = _shortest_paths(g, source, frozenset(goals))
    if not candidates:
        raise NoPath(device.id, source, concept)
    ranked = []
    for nodes in candidates:
        steps = tuple(_best_edge(g, a, b, wanted) for a, b in zip(nodes[:-1], nodes[1:], strict=True))
        accepted = sum(len(wanted.intersection(t.accepts)) for t in steps)
        ranked.append((-accepted, nodes, tuple(t.line or 0 for t in steps), steps))
    _, nodes, _, steps = min(ranked)
    return Path(source, nodes[-1], steps)


def _shortest_paths(
    g: dict[str, dict[str, list[ChartTransition]]], source: str, goals: frozenset[str]
) -> list[tuple[str, ...]]:
    """Every path of least weight from ``source`` to any state of ``goals`` (Dijkstra, all predecessors kept).

    An edge weighs the fewest commands among its parallel transitions. A goal reached on the
    way to another goal at no extra weight yields both paths, as a search to one virtual goal
    node behind all goals would.
    """
    dist = {source: 0}
    preds: dict[str, list[str]] = {source: []}
    heap = [(0, source)]
    done: set[str] = set()
    while heap:
        d, u = heapq.heappop(heap)
        if u in done:
            continue
        done.add(u)
        for v, transitions in g.get(u, {}).items():
            nd = d + min(commands(t) for t in transitions)
            if v not in dist or nd < dist[v]:
                dist[v], preds[v] = nd, [u]
                heapq.heappush(heap, (nd, v))
            elif nd == dist[v] and u not in preds[v] and v != source:
                preds[v].append(u)
    reached = [s for s in goals if s in dist]
    if not reached:
        return []
    best = min(dist[s] for s in reached)
    paths: list[tuple[str, ...]] = []
    for goal in sorted(s for s in reached if dist[s] == best):
        paths.extend(_paths_back(preds, source, goal, ()))
    return paths


def _paths_back(preds: dict[str, list[str]], source: str, node: str, after: tuple[str, ...]) -> list[tuple[str, ...]]:
    """The paths from ``source`` to ``node`` through ``preds``, followed by ``after`` (no state twice)."""
    if node == source:
        return [(source, *after)]
    out: list[tuple[str, ...]] = []
    for p in preds[node]:
        if p not in after and p != node:
            out.extend(_paths_back(preds, source, p, (node, *after)))
    return out


def _best_edge(
    g: dict[str, dict[str, list[ChartTransition]]], a: str, b: str, wanted: frozenset[str]
) -> ChartTransition:
    return min(g[a][b], key=lambda t: (commands(t), -len(wanted.intersection(t.accepts)), t.line or 0))
