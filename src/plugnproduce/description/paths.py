"""Path search in a Device State Chart (paper section 6.1).

A General Process State Chart says which state concept a device must reach next; the
Device State Chart says how. The chart becomes a networkx multigraph whose edges are
its transitions; a path to any state whose concept is subsumed by the wanted one is
searched, shortest by number of device commands; among equally short paths the one
whose requests accept more of the parameters the step hands over wins (a lift with a
pose moves to it rather than homing), then the one first by state ids, so the result
never depends on dict or set order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.ontology.taxonomy import Taxonomy

if TYPE_CHECKING:  # networkx is imported on first use: a command that searches no path never pays for it
    import networkx as nx

_GOAL = "\0goal"


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


def chart_graph(device: DeviceDescription) -> nx.MultiDiGraph:
    """The Device State Chart as a graph: one edge per transition, weighted by its commands."""
    import networkx as nx

    g = nx.MultiDiGraph()
    g.add_nodes_from(s.id for s in device.states)
    for i, t in enumerate(device.transitions):
        g.add_edge(t.source, t.target, key=i, transition=t, weight=commands(t))
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
    import networkx as nx

    g = chart_graph(device)
    for s in goals:
        g.add_edge(s, _GOAL, key=-1, weight=0)
    try:
        candidates = list(nx.all_shortest_paths(g, source, _GOAL, weight="weight"))
    except nx.NetworkXNoPath as exc:
        raise NoPath(device.id, source, concept) from exc
    ranked = []
    for nodes in candidates:
        steps = tuple(_best_edge(g, a, b, wanted) for a, b in zip(nodes[:-2], nodes[1:-1], strict=True))
        accepted = sum(len(wanted.intersection(t.accepts)) for t in steps)
        ranked.append((-accepted, tuple(nodes[:-1]), tuple(t.line or 0 for t in steps), steps))
    _, nodes, _, steps = min(ranked)
    return Path(source, nodes[-1], steps)


def _best_edge(g: nx.MultiDiGraph, a: str, b: str, wanted: frozenset[str]) -> ChartTransition:
    edges = g.get_edge_data(a, b).values()
    best = min(edges, key=lambda e: (e["weight"], -len(wanted.intersection(e["transition"].accepts)),
                                     e["transition"].line or 0))
    return best["transition"]  # type: ignore[no-any-return]
