"""What a microstep enters, in the W3C algorithm's terms (https://www.w3.org/TR/scxml/#AlgorithmforSCXMLInterpretation).

:func:`effective_targets` and :func:`domain_of` are the specification's
``getEffectiveTargetStates`` and ``getTransitionDomain`` once history is known;
:class:`EntryBuilder` is its ``computeEntrySet`` with ``addDescendantStatesToEnter`` and
``addAncestorStatesToEnter``: the states a set of transitions enters, the compound states
entered by default (whose ``<initial>`` content runs) and the content of history defaults.
"""

from __future__ import annotations

from plugnproduce.statechart.runtime.actions import Block
from plugnproduce.statechart.runtime.compiled import ROOT, CState, CTransition, transition_domain

History = dict[CState, list[CState]]
"""The recorded history: history pseudo-state → the states it remembers."""


def effective_targets(t: CTransition, history: History) -> list[CState]:
    """The targets of ``t`` with each history state replaced by what it stands for now."""
    out: list[CState] = []
    for s in t.targets:
        if not s.is_history:
            out.append(s)
        elif s in history:
            out.extend(history[s])
        else:
            assert s.initial is not None  # the compiler gives every history a default transition
            out.extend(effective_targets(s.initial, history))
    return out


def domain_of(t: CTransition, history: History) -> CState | None:
    """The transition domain of ``t`` (None for a targetless transition, which exits nothing)."""
    if t.domain is not None or not t.targets:
        return t.domain
    return transition_domain(t, effective_targets(t, history))


class EntryBuilder:
    """The entry set of a microstep, built one transition at a time."""

    def __init__(self, history: History) -> None:
        self.history = history
        self.states: set[CState] = set()
        self.default_entry: set[CState] = set()
        self.history_content: dict[CState, Block] = {}
        self.saw_history = False

    def add(self, t: CTransition) -> None:
        """Add what taking ``t`` enters."""
        if not t.targets:
            return
        for s in t.targets:
            self.descendants(s)
        domain = domain_of(t, self.history)
        for s in effective_targets(t, self.history):
            self.ancestors(s, domain)

    def descendants(self, state: CState) -> None:
        """Add ``state`` and what entering it enters below it."""
        if state.is_history:
            self.saw_history = True
            parent = state.parent
            assert parent is not None  # a history state always has a parent
            if state in self.history:
                targets = self.history[state]
            else:
                assert state.initial is not None  # the compiler gives every history a default transition
                if state.initial.actions:
                    self.history_content[parent] = state.initial.actions
                targets = state.initial.targets
            for s in targets:
                self.descendants(s)
            for s in targets:
                self.ancestors(s, parent)
            return
        self.states.add(state)
        if state.is_compound:
            self.default_entry.add(state)
            assert state.initial is not None  # a compound state has an initial transition
            for s in state.initial.targets:
                self.descendants(s)
            for s in state.initial.targets:
                self.ancestors(s, state)
        elif state.is_parallel:
            self._children_of_parallel(state)

    def ancestors(self, state: CState, ancestor: CState | None) -> None:
        """Add the proper ancestors of ``state`` below ``ancestor``, completing parallel ones."""
        for anc in state.ancestors:
            if anc is ancestor or anc.kind == ROOT:
                return
            self.states.add(anc)
            if anc.is_parallel:
                self._children_of_parallel(anc)

    def _children_of_parallel(self, state: CState) -> None:
        for child in state.substates:
            if child not in self.states and child.descendants.isdisjoint(self.states):
                self.descendants(child)
