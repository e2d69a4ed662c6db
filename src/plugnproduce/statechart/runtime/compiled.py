"""The chart prepared for running: states and transitions with everything the algorithm asks
for precomputed once (document order, ancestors, descendants, default entries, static
transition domains and event matchers), executable content compiled to actions.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

from plugnproduce.statechart.model import (
    Chart,
    Data,
    Final,
    History,
    Parallel,
    State,
    StateNode,
    Transition,
)
from plugnproduce.statechart.runtime.actions import Block, compile_block, compile_donedata, compile_invoke
from plugnproduce.statechart.runtime.evaluator import Evaluator, Expr

if TYPE_CHECKING:
    from plugnproduce.statechart.runtime.session import EntrySet

log = logging.getLogger(__name__)

ROOT, ATOMIC, COMPOUND, PARALLEL, FINAL, HISTORY = range(6)


class CState:
    """A state (or the ``<scxml>`` root, or a history pseudo-state) ready to run."""

    __slots__ = ("idx", "id", "kind", "node", "parent", "ancestors", "substates", "histories",
                 "descendants", "initial", "evented", "eventless", "onentry", "onexit",
                 "invokes", "data", "donedata", "deep", "is_atomic", "is_final", "is_parallel", "is_compound",
                 "is_history", "eventless_chain", "evented_chain")

    def __init__(self, idx: int, state_id: str, kind: int, node: Any, parent: CState | None):
        self.idx = idx
        self.id = state_id
        self.kind = kind
        self.node = node
        self.parent = parent
        self.ancestors: tuple[CState, ...] = (parent,) + parent.ancestors if parent is not None else ()
        self.substates: list[CState] = []
        self.histories: list[CState] = []
        self.descendants: frozenset[CState] = frozenset()
        self.initial: CTransition | None = None
        self.evented: list[CTransition] = []
        self.eventless: list[CTransition] = []
        self.onentry: list[Block] = []
        self.onexit: list[Block] = []
        self.invokes: list[Any] = []
        self.data: list[Data] = []
        self.donedata: Any = None
        self.deep = False
        self.is_atomic = kind in (ATOMIC, FINAL)
        self.is_final = kind == FINAL
        self.is_parallel = kind == PARALLEL
        self.is_compound = kind in (COMPOUND, ROOT)
        self.is_history = kind == HISTORY
        # the transitions of the state, then of each ancestor: the order in which they are tried
        self.eventless_chain: tuple[CTransition, ...] = ()
        self.evented_chain: tuple[CTransition, ...] = ()

    def __repr__(self) -> str:
        return f"<CState {self.id}>"


class CTransition:
    """A transition ready to run, with a fast event matcher and (when static) its domain."""

    __slots__ = ("source", "node", "events", "exact", "prefixes", "wildcard", "cond", "targets", "internal",
                 "actions", "has_history", "domain", "entry_cache")

    def __init__(self, source: CState, node: Transition, evaluator: Evaluator, actions: Block):
        self.source = source
        self.node = node
        descriptors = [_descriptor(d) for d in node.events]
        self.events = node.event
        self.wildcard = "*" in descriptors
        self.exact = frozenset(descriptors)
        self.prefixes = tuple(d + "." for d in descriptors)
        cond = node.cond if node.cond is not None and node.cond.strip() else None  # an empty cond is no cond
        self.cond: Expr | None = None if cond is None else evaluator.expr(cond)
        self.targets: list[CState] = []
        self.internal = node.type == "internal"
        self.actions = actions
        self.has_history = False
        self.domain: CState | None = None
        self.entry_cache: EntrySet | None = None

    def matches(self, name: str) -> bool:
        """True when the event ``name`` matches one of the transition's descriptors."""
        return self.wildcard or name in self.exact or name.startswith(self.prefixes)

    def __repr__(self) -> str:
        return f"<CTransition {self.source.id} -> {[t.id for t in self.targets]}>"


def _descriptor(text: str) -> str:
    if text == "*":
        return text
    if text.endswith(".*"):
        text = text[:-2]
    return text.rstrip(".")


class CompiledChart:
    """All states of a chart in document order, with look-ups by id."""

    def __init__(self, chart: Chart, evaluator: Evaluator, where: str):
        self.chart = chart
        self.evaluator = evaluator
        self.where = where
        self.states: list[CState] = []
        self.by_id: dict[str, CState] = {}
        self.transitions: list[CTransition] = []
        self.root = self._state(chart, None, ROOT)
        self._link()
        self.scripts = [compile_block(evaluator, [s], where) for s in chart.scripts]

    # --- building --------------------------------------------------------------------

    def _state(self, node: Any, parent: CState | None, kind: int) -> CState:
        idx = len(self.states)
        state_id = getattr(node, "id", None) or f"_state{idx}"
        cs = CState(idx, state_id, kind, node, parent)
        self.states.append(cs)
        self.by_id.setdefault(state_id, cs)
        if isinstance(node, History):
            cs.deep = node.type == "deep"
            return cs
        if not isinstance(node, Chart):
            cs.onentry = [compile_block(self.evaluator, b.actions, self.where) for b in node.onentry]
            cs.onexit = [compile_block(self.evaluator, b.actions, self.where) for b in node.onexit]
        cs.data = list(node.data) if not isinstance(node, Final) else []
        if isinstance(node, Final):
            cs.donedata = compile_donedata(self.evaluator, node.donedata, self.where)
            return cs
        if isinstance(node, State | Parallel):
            cs.invokes = [compile_invoke(self.evaluator, inv, self.where) for inv in node.invokes]
        for child in node.children:
            cs_child = self._state(child, cs, _kind(child))
            (cs.histories if cs_child.is_history else cs.substates).append(cs_child)
        return cs

    def _link(self) -> None:
        """Second pass, once every state exists: descendants, transitions, initial entries."""
        for cs in reversed(self.states):
            below: set[CState] = set()
            for child in cs.substates + cs.histories:
                below.add(child)
                below |= child.descendants
            cs.descendants = frozenset(below)
        for cs in self.states:
            node = cs.node
            if isinstance(node, State | Parallel):
                own = [self._transition(cs, t) for t in node.transitions]
                cs.evented = [t for t in own if t.exact]
                cs.eventless = [t for t in own if not t.exact]
            if isinstance(node, History):
                cs.initial = self._transition(cs, node.transition or self._parent_default(cs))
            elif cs.is_compound:
                cs.initial = self._initial(cs)
        for cs in self.states:
            lineage = (cs, *cs.ancestors)
            cs.eventless_chain = tuple(t for s in lineage for t in s.eventless)
            cs.evented_chain = tuple(t for s in lineage for t in s.evented)
        for t in self.transitions:
            self._domain(t)

    def _transition(self, source: CState, node: Transition) -> CTransition:
        t = CTransition(source, node, self.evaluator, compile_block(self.evaluator, node.actions, self.where))
        for target in node.targets:
            cs = self.by_id.get(target)
            if cs is None:  # only in inline child charts; the reader refuses these at the top
                log.warning("%s: transition target %r does not exist; the transition is dropped", self.where, target)
                t.targets = []
                t.exact = frozenset()
                t.prefixes = ()
                t.wildcard = False
                t.cond = self.evaluator.expr("False")
                break
            t.targets.append(cs)
        t.has_history = any(s.is_history for s in t.targets)
        self.transitions.append(t)
        return t

    def _initial(self, cs: CState) -> CTransition | None:
        node = cs.node
        element = getattr(node, "initial_element", None)
        if element is not None:
            return self._transition(cs, element.transition)
        names = node.initial if isinstance(node, State | Chart) else []
        if not names:
            if not cs.substates:
                return None
            names = [cs.substates[0].id]
        return self._transition(cs, Transition(targets=list(names), line=node.line))

    def _parent_default(self, history: CState) -> Transition:
        """A history without a transition (the schema asks for one) defaults to its parent's initial states."""
        initial = history.parent.initial if history.parent is not None else None
        return Transition(targets=[s.id for s in initial.targets] if initial is not None else [],
                          line=history.node.line)

    def _domain(self, t: CTransition) -> None:
        """The transition domain, when it does not depend on history (else computed when taken)."""
        if t.has_history or not t.targets:
            return
        t.domain = transition_domain(t, t.targets)


def _kind(node: StateNode) -> int:
    if isinstance(node, Parallel):
        return PARALLEL
    if isinstance(node, Final):
        return FINAL
    if isinstance(node, History):
        return HISTORY
    return ATOMIC if node.is_atomic else COMPOUND


def transition_domain(t: CTransition, targets: list[CState]) -> CState:
    """The compound state (or root) whose descendants the transition exits and enters."""
    source = t.source
    if t.internal and source.is_compound and all(s in source.descendants for s in targets):
        return source
    return lcca([source, *targets])


def lcca(states: list[CState]) -> CState:
    """The least common compound ancestor of ``states`` (the root at worst)."""
    head, rest = states[0], states[1:]
    if head.kind == ROOT:
        return head
    for anc in head.ancestors:
        if anc.is_compound and all(s in anc.descendants for s in rest):
            return anc
    return head.ancestors[-1]


__all__ = ["CState", "CTransition", "CompiledChart", "lcca", "transition_domain"]
