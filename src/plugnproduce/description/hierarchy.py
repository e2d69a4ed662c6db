"""A Device State Chart with compound states, as the states a device can be in (SCXML semantics).

A device chart may nest states: a ``Running`` superstate holding ``Starting``, ``Execute`` and
``Completing``, or a superstate whose ``Abort`` applies to every state inside it. Planning, path
search and the reasoner work on the *atomic* states, the ones a device reports being in; this
module lifts each of them with what W3C SCXML gives it:

- its concepts: its own ``pnp:concept`` first, then those of the compound states around it,
  nearest first (a device in ``Execute`` inside ``Running`` is in a running state);
- its transitions: its own, then those of each enclosing state, unless a transition nearer to it
  already takes the same event unconditionally (SCXML selects transitions innermost first);
- each transition's target entered as SCXML enters it: a compound target enters its initial
  child, down to an atomic state; the commands the device sends on the way are the exited
  states' ``onexit`` (innermost first), the transition's own, then the entered states'
  ``onentry`` (outermost first), with any ``<initial>`` transition's on the way.

``<parallel>`` and ``<history>`` stay refused: a device is in one state at a time.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from plugnproduce.description.model import ChartState, ChartTransition, Command
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.iris import concept_iri
from plugnproduce.statechart.model import (
    CONCEPT,
    Chart,
    Final,
    History,
    Node,
    Parallel,
    Send,
    State,
    Transition,
    pnp,
    walk,
)

ACCEPTS = pnp("accepts")
MAX_TRANSITIONS = 100_000
MAX_SENDS = 1_000_000
"""The most events the lifted transitions may send in all (each counts what the states it leaves and enters send)."""
"""The most transitions a chart's atomic states may take (a compound state's count once per state inside it)."""
Leaf = State | Final


@dataclass(frozen=True)
class DeviceChart:
    """What a description takes from a Device State Chart."""

    initial: str
    states: tuple[ChartState, ...]
    """The atomic states, in document order."""
    compounds: tuple[ChartState, ...]
    """The compound states, in document order (their own concept, what encloses them)."""
    transitions: tuple[ChartTransition, ...]
    """Every transition as taken from an atomic state."""


@dataclass
class _Tree:
    """The chart's states by id, each with the compound state around it (None: the chart)."""

    path: str | Path
    nodes: dict[str, Leaf] = field(default_factory=dict)
    parent: dict[str, str | None] = field(default_factory=dict)
    order: list[Leaf] = field(default_factory=list)
    sends: int = 0
    _entry: dict[str, list[Command]] = field(default_factory=dict)
    _exit: dict[str, list[Command]] = field(default_factory=dict)
    _own: dict[int, list[Command]] = field(default_factory=dict)

    def add(self, children: Iterable[Node], parent: str | None) -> None:
        for c in children:
            if isinstance(c, Parallel | History):
                kind = "parallel" if isinstance(c, Parallel) else "history"
                raise DescriptionError(f"a Device State Chart may nest <state>s but has no <{kind}>: a device is "
                                       "in one state at a time; expected <state> and <final> only", self.path, c.line)
            if isinstance(c, State | Final):
                sid = c.id or ""
                if sid in self.nodes:
                    raise DescriptionError(f"two states of the chart are called {sid!r}" if sid else
                                           "two states of the chart have no id; expected an id on each", self.path,
                                           c.line)
                self.nodes[sid], self.parent[sid] = c, parent
                self.order.append(c)
                if isinstance(c, State):
                    self.add(c.children, sid)

    def chain(self, sid: str | None) -> list[str]:
        """``sid`` and the compound states around it, innermost first."""
        out: list[str] = []
        while sid is not None:
            out.append(sid)
            sid = self.parent.get(sid)
        return out

    def entry(self, sid: str) -> list[Command]:
        """What a state sends on entry (read once per state)."""
        if sid not in self._entry:
            self._entry[sid] = _sends(self.nodes[sid].onentry)
        return self._entry[sid]

    def exit(self, sid: str) -> list[Command]:
        """What a state sends on exit (read once per state)."""
        if sid not in self._exit:
            self._exit[sid] = _sends(self.nodes[sid].onexit)
        return self._exit[sid]

    def sent_by(self, t: Transition) -> list[Command]:
        """What a transition's own content sends (read once per transition)."""
        if id(t) not in self._own:
            self._own[id(t)] = _sends([t])
        return self._own[id(t)]

    def counted(self, sends: list[Command], line: int | None) -> tuple[Command, ...]:
        """``sends`` for one more lifted transition, within the budget of all the chart's lifted sends."""
        self.sends += len(sends)
        if self.sends > MAX_SENDS:
            raise DescriptionError(f"the chart's transitions send more than {MAX_SENDS} events in all, counting what "
                                   "the states they leave and enter send; at most that many are accepted", self.path,
                                   line)
        return tuple(sends)

    def state(self, sid: str, line: int | None) -> Leaf:
        if sid not in self.nodes:
            raise DescriptionError(f"a transition targets {sid!r}, which is not a state of the chart", self.path, line)
        return self.nodes[sid]


def _sends(nodes: Iterable[Node]) -> list[Command]:
    """The protocol events sent anywhere below ``nodes``, in document order."""
    out: list[Command] = []
    for top in nodes:
        for node in walk(top, into_charts=False):
            if isinstance(node, Send):
                cmd = Command.parse(node.event or "")
                if cmd is not None and cmd.kind == "event":
                    out.append(cmd)
    return out


def _concept(node: Node) -> str | None:
    value = node.extra_attrs.get(CONCEPT)
    return concept_iri(value) if value else None


def _default_child(tree: _Tree, state: State) -> tuple[str, list[Command]]:
    """The child a compound state enters by default, and what its ``<initial>`` transition sends."""
    if state.initial_element is not None and state.initial_element.transition.targets:
        t = state.initial_element.transition
        return t.targets[0], _sends([t])
    if state.initial:
        return state.initial[0], []
    first = next((c for c in state.children if isinstance(c, State | Final)), None)
    return (first.id or "") if first is not None else "", []


def _enter(tree: _Tree, domain: str | None, target: str, line: int | None) -> tuple[str, list[Command]]:
    """The atomic state entering ``target`` from inside ``domain`` ends in, and what the entered states send."""
    tree.state(target, line)
    chain = tree.chain(target)
    entered = chain[: chain.index(domain)] if domain in chain else chain
    sends: list[Command] = []
    for sid in reversed(entered):
        sends += tree.entry(sid)
    node = tree.nodes[target]
    while isinstance(node, State) and not node.is_atomic:
        child, initial_sends = _default_child(tree, node)
        sends += initial_sends
        below = tree.chain(tree.state(child, node.line).id)
        if node.id not in below[1:]:
            raise DescriptionError(f"state {node.id!r} starts in {child!r}, which is not inside it", tree.path,
                                   node.line)
        for sid in reversed(below[: below.index(node.id or "")]):
            sends += tree.entry(sid)
        node = tree.nodes[child]
    return node.id or "", sends


def initial_state(chart: Chart, tree: _Tree) -> str:
    """The atomic state the chart starts in."""
    if not tree.order:
        return ""
    first = chart.initial[0] if chart.initial else (tree.order[0].id or "")
    if first not in tree.nodes:
        return first  # no state of the chart: the structure checks say so, at the chart's line
    return _enter(tree, None, first, chart.line)[0]


def _domain(tree: _Tree, holder: str, target: str, t: Transition) -> str | None:
    """The state a transition leaves and enters inside of (None: the chart itself)."""
    target_chain = tree.chain(target)
    node = tree.nodes[holder]
    if t.type == "internal" and isinstance(node, State) and not node.is_atomic and holder in target_chain[1:]:
        return holder
    return next((a for a in tree.chain(holder)[1:] if a in target_chain[1:]), None)


def _descriptor(d: str) -> str:
    """An event descriptor without the ``.*`` or ``.`` it may end with (``error.*`` matches as ``error``)."""
    return d[:-2] if d.endswith(".*") else d.rstrip(".")


@dataclass
class _Taken:
    """The events the transitions nearer to an atomic state always take (no ``cond``), as descriptors."""

    descriptors: set[str] = field(default_factory=set)
    eventless: bool = False

    def add(self, transitions: Iterable[Transition]) -> None:
        for u in transitions:
            if not u.cond:
                self.descriptors.update(_descriptor(d) for d in u.events)
                self.eventless = self.eventless or not u.events

    def shadows(self, t: Transition) -> bool:
        """Whether every event ``t`` takes is taken first by a transition nearer to the atomic state."""
        if not t.events:
            return self.eventless
        return all(self._matched(e) for e in t.events)

    def _matched(self, event: str) -> bool:
        if "*" in self.descriptors:
            return True
        parts = event.split(".")
        return any(".".join(parts[:n]) in self.descriptors for n in range(1, len(parts) + 1))


def _lifted(tree: _Tree, leaf: Leaf, holder: str, t: Transition) -> ChartTransition:
    accepts = tuple(concept_iri(a) for a in t.extra_attrs.get(ACCEPTS, "").split())
    source = leaf.id or ""
    if not t.targets:
        return ChartTransition(source, source, t.event, tree.counted(tree.sent_by(t), t.line), accepts, t.line,
                               _concept(t), holder)
    if len(t.targets) > 1:
        raise DescriptionError("a transition of a Device State Chart has one target; found "
                               f"{len(t.targets)}", tree.path, t.line)
    domain = _domain(tree, holder, t.targets[0], t)
    chain = tree.chain(source)
    exited = chain[: chain.index(domain)] if domain in chain else chain
    sends = [c for sid in exited for c in tree.exit(sid)] + tree.sent_by(t)
    target, entered = _enter(tree, domain, t.targets[0], t.line)
    return ChartTransition(source, target, t.event, tree.counted(sends + entered, t.line), accepts, t.line,
                           _concept(t), holder)


def _leaf_transitions(tree: _Tree, leaf: Leaf) -> Iterator[ChartTransition]:
    taken = _Taken()
    for holder in tree.chain(leaf.id or ""):
        node = tree.nodes[holder]
        own = node.transitions if isinstance(node, State) else []
        for t in own:
            done = f"done.state.{holder}"
            if holder != leaf.id and t.event == done and not isinstance(leaf, Final):
                continue  # a compound's done event comes only once a final child is entered
            if holder == leaf.id or not taken.shadows(t):
                yield _lifted(tree, leaf, holder, t)
        taken.add(own)


def _count(tree: _Tree) -> int:
    """How many transitions the atomic states take, before shadowing: what lifting them costs at most."""
    own = {sid: len(n.transitions) if isinstance(n, State) else 0 for sid, n in tree.nodes.items()}
    leaves = (n for n in tree.order if not (isinstance(n, State) and not n.is_atomic))
    return sum(own[a] for n in leaves for a in tree.chain(n.id or ""))


def device_chart(chart: Chart, path: str | Path) -> DeviceChart:
    """The initial state, atomic and compound states and transitions of a Device State Chart read from ``path``."""
    tree = _Tree(path)
    tree.add(chart.children, None)
    lifted = _count(tree)
    if lifted > MAX_TRANSITIONS:
        raise DescriptionError(f"the chart's states take {lifted} transitions, counting each compound state's once "
                               f"for every state inside it; at most {MAX_TRANSITIONS} are accepted", path, chart.line)
    states: list[ChartState] = []
    compounds: list[ChartState] = []
    transitions: list[ChartTransition] = []
    for node in tree.order:
        sid = node.id or ""
        around = tree.chain(sid)[1:]
        concepts = tuple(dict.fromkeys(c for c in (_concept(tree.nodes[a]) for a in [sid, *around]) if c))
        within = tuple(reversed(around))
        if isinstance(node, State) and not node.is_atomic:
            compounds.append(ChartState(sid, _concept(node), node.line, within=within))
            continue
        states.append(ChartState(sid, concepts[0] if concepts else None, node.line, concepts, within))
        transitions += _leaf_transitions(tree, node)
    return DeviceChart(initial_state(chart, tree), tuple(states), tuple(compounds), tuple(transitions))
