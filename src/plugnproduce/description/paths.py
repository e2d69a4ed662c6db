"""Path search in a Device State Chart (paper section 6.1).

A General Process State Chart says which state concept a device must reach next; the
Device State Chart says how. The chart is a graph whose edges are its transitions; a
path to any state whose concept is subsumed by the wanted one is searched, shortest by
number of device commands (Dijkstra's, all shortest paths); among equally short paths the one
whose requests accept more of the parameters the step hands over wins (a lift with a
pose moves to it rather than homing), then the one first by state ids, so the result
never depends on dict or set order.

A parameter the step hands over is not dropped while the chart has a way to take it: when the
shortest path takes fewer of them than some other path whose every request takes one of them, that
path wins (the one taking the most, shortest among those). So a region from a state to another state
of the same concept (Open → Open, handing over an opening angle) goes through the device's request for
it (open → configuring → open) instead of staying put; without parameters it stays put. A route that
would need another request on the way (close the gripper to reach its angle request) is not taken:
the plausibility check says the value would be lost.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Hashable, Mapping
from typing import TypeVar

from plugnproduce.deferred import dataclass
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


N = TypeVar("N", bound=Hashable)
"""A node of a graph of chart transitions: a state, or a state paired with what was taken on the way."""

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
    if not goals:
        raise NoPath(device.id, source, concept)
    edges = chart_edges(device)
    if source in goals:
        shortest = ChartPath(source, source, ())
    elif source not in edges:
        raise NoPath(device.id, source, concept)
    else:
        shortest = _shortest_path(edges, source, set(goals), wanted, device.id, concept)
    takeable = handed_over(device.transitions, wanted)
    if source not in edges or takeable <= handed_over(shortest.steps, wanted):
        return shortest
    taking = _taking_most(edges, source, set(goals), takeable)
    if taking is None or len(handed_over(taking.steps, wanted)) <= len(handed_over(shortest.steps, wanted)):
        return shortest
    return taking


def handed_over(steps: tuple[ChartTransition, ...], wanted: frozenset[str]) -> frozenset[str]:
    """The quantities of ``wanted`` that the requests along ``steps`` take."""
    return frozenset(q for t in steps if t.request for q in t.accepts if q in wanted)


def _shortest_path(edges: Edges, source: str, goals: set[str], wanted: frozenset[str], device: str,
                   concept: str) -> ChartPath:
    """Among the paths with the fewest commands, the one taking the most of ``wanted``, then first by state ids."""
    candidates = _shortest(edges, source, goals)
    if not candidates:
        raise NoPath(device, source, concept)
    ranked = []
    for nodes in candidates:
        steps = tuple(_best_edge(edges, a, b, wanted) for a, b in zip(nodes[:-1], nodes[1:], strict=True))
        accepted = sum(len(wanted.intersection(t.accepts)) for t in steps)
        ranked.append((-accepted, tuple(nodes), tuple(t.line or 0 for t in steps), steps))
    _, best, _, steps = min(ranked)
    return ChartPath(source, best[-1], steps)


def _taking_most(edges: Edges, source: str, goals: set[str], wanted: frozenset[str]) -> ChartPath | None:
    """The path from ``source`` to a goal state whose requests take the most of ``wanted`` (at least one), the
    fewest commands among those, then first by state ids and lines; None if no path takes any. Every request on
    it takes some of ``wanted``: the device is not closed, homed or moved on the way only to reach a request
    that takes a parameter (the plausibility check then says the value would be lost).

    The search runs on the chart paired with what is taken so far: a state may be passed again once more is
    taken (open → configuring → open), and there are finitely many such pairs."""
    start: Pair = (source, frozenset())
    product = _taking(edges, start, wanted)
    for count in range(len(wanted), 0, -1):
        ends = {pair for pair in product if pair[0] in goals and len(pair[1]) == count}
        candidates = _shortest(product, start, ends) if ends else []
        ranked = []
        for pairs in candidates:
            steps = tuple(_best_edge(product, a, b, wanted) for a, b in zip(pairs[:-1], pairs[1:], strict=True))
            ranked.append((tuple(state for state, _ in pairs), tuple(t.line or 0 for t in steps), steps))
        if ranked:
            states, _, steps = min(ranked)
            return ChartPath(source, states[-1], steps)
    return None


Pair = tuple[str, frozenset[str]]
"""A chart state and the quantities taken on the way to it."""


def _taking(edges: Edges, start: Pair, wanted: frozenset[str]) -> dict[Pair, dict[Pair, list[ChartTransition]]]:
    """The chart's transitions between (state, quantities taken) pairs reachable from ``start``: those that send
    no request, and those whose request takes some of ``wanted``."""
    out: dict[Pair, dict[Pair, list[ChartTransition]]] = {start: {}}
    todo = [start]
    while todo:
        state, taken = here = todo.pop()
        for target, transitions in edges[state].items():
            for t in transitions:
                if t.request and not handed_over((t,), wanted):
                    continue  # no other request on the way: it would move the device in ways the step does not say
                there = (target, taken | handed_over((t,), wanted))
                out[here].setdefault(there, []).append(t)
                if there not in out:
                    out[there] = {}
                    todo.append(there)
    return out


def _shortest(edges: Mapping[N, Mapping[N, list[ChartTransition]]], source: N, goals: set[N]) -> list[list[N]]:
    """Every path from ``source`` to a goal state that carries the fewest commands, without a state twice.

    Dijkstra's distances (an edge weighs the fewest commands of the transitions it stands for), then every
    simple path back through the predecessors that keep a distance shortest: the paths networkx's
    ``all_shortest_paths`` gives, without importing networkx (most of a command's start-up)."""
    dist = {source: 0}
    order = itertools.count()  # no two nodes are compared
    heap = [(0, next(order), source)]
    while heap:
        d, _, a = heapq.heappop(heap)
        if d > dist[a]:
            continue
        for b, ts in edges[a].items():
            nd = d + min(commands(t) for t in ts)
            if nd < dist.get(b, nd + 1):
                dist[b] = nd
                heapq.heappush(heap, (nd, next(order), b))
    reached = [g for g in goals if g in dist]
    if not reached:
        return []
    best = min(dist[g] for g in reached)
    pred: dict[N, list[N]] = {}
    for a, targets in edges.items():
        for b, ts in targets.items():
            if a in dist and b in dist and dist[a] + min(commands(t) for t in ts) == dist[b]:
                pred.setdefault(b, []).append(a)
    out: list[list[N]] = []
    for goal in (g for g in reached if dist[g] == best):
        out += _back(pred, source, [goal])
    return out


def _back(pred: dict[N, list[N]], source: N, path: list[N]) -> list[list[N]]:
    """The simple paths from ``source`` that end with ``path`` (reversed), through ``pred``."""
    out = [path[::-1]] if path[-1] == source else []
    for a in pred.get(path[-1], ()):
        if a not in path:
            out += _back(pred, source, [*path, a])
    return out


def _best_edge(edges: Mapping[N, Mapping[N, list[ChartTransition]]], a: N, b: N,
               wanted: frozenset[str]) -> ChartTransition:
    return min(edges[a][b], key=lambda t: (commands(t), -len(wanted.intersection(t.accepts)), t.line or 0))
