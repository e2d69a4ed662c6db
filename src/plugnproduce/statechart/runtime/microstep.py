"""The microstep, in the W3C algorithm's terms (https://www.w3.org/TR/scxml/#AlgorithmforSCXMLInterpretation):
``microstep``, ``exitStates`` (with the history it records) and ``enterStates`` (with the ``done.state``
events of final states), mixed into the interpreter. What the states entered are is
:mod:`~plugnproduce.statechart.runtime.entry`'s.
"""

from __future__ import annotations

from typing import Any

from plugnproduce.statechart.runtime.compiled import ROOT, CState, CTransition
from plugnproduce.statechart.runtime.entry import EntryBuilder, domain_of
from plugnproduce.statechart.runtime.evaluator import EvaluationError
from plugnproduce.statechart.runtime.events import STATE_ENTERED, STATE_EXITED, TRANSITION_TAKEN, Event, TakenTransition
from plugnproduce.statechart.runtime.session import EntrySet, MicrostepSession


def doc_order(state: CState) -> int:
    """A state's place in document order (the key to sort states by)."""
    return state.idx


class Microstep:
    """Exiting and entering states: the microstep half of a session (mixed into the interpreter)."""

    running: bool
    final_state: str | None
    _atomic: list[CState] | None

    def _microstep(self: MicrostepSession, enabled: list[CTransition]) -> None:
        self._exit_states(enabled)
        for t in enabled:
            if self._step is not None:
                self._step.transitions.append(TakenTransition(t.source.id, tuple(s.id for s in t.targets), t.events))
            if self._observers:
                self._notify(TRANSITION_TAKEN, transition=t.node, source=t.source.id)
            if t.actions:
                self._run(t.actions)
        self._enter(enabled)

    def _exits(self: MicrostepSession, t: CTransition) -> set[CState]:
        """The active states that taking ``t`` exits."""
        domain = domain_of(t, self._history)
        return self._config & domain.descendants if domain is not None else set()

    def _exit_set(self: MicrostepSession, transitions: list[CTransition]) -> list[CState]:
        """The states the transitions exit, in exit order (reverse document order)."""
        return sorted(set().union(*map(self._exits, transitions)), key=doc_order, reverse=True)

    def _exit_states(self: MicrostepSession, enabled: list[CTransition]) -> None:
        to_exit = self._exit_set(enabled)
        if not to_exit:
            return
        self._to_invoke.difference_update(to_exit)
        for s in to_exit:
            for h in s.histories:
                if h.deep:
                    self._history[h] = [x for x in self._config if x.is_atomic and x in s.descendants]
                else:
                    self._history[h] = [x for x in self._config if x.parent is s]
        for s in to_exit:
            self._exit_one(s)
        self._atomic = None

    def _exit_one(self: MicrostepSession, s: CState) -> None:
        for block in s.onexit:
            self._run(block)
        if self._invocations:
            self._cancel_invokes(s)
        self._config.discard(s)
        if self._step is not None:
            self._step.exited.append(s.id)
        if self._observers:
            self._notify(STATE_EXITED, state=s.id)

    def _enter(self: MicrostepSession, enabled: list[CTransition]) -> None:
        states, default_entry, history_content = self._entry_set(enabled)
        for s in states:
            self._config.add(s)
            self._atomic = None
            self._to_invoke.add(s)
            if self._step is not None:
                self._step.entered.append(s.id)
            if self._observers:
                self._notify(STATE_ENTERED, state=s.id)
            if self._late and s not in self._data_ready:
                self._bind(s)
            for block in s.onentry:
                self._run(block)
            if s in default_entry and s.initial is not None and s.initial.actions:
                self._run(s.initial.actions)
            if s in history_content:
                self._run(history_content[s])
            if s.is_final:
                self._entered_final(s)

    def _entered_final(self: MicrostepSession, s: CState) -> None:
        parent = s.parent
        assert parent is not None  # a final state is never the root
        if parent.kind == ROOT:
            self.running = False
            self.final_state = s.id
            return
        self.internal.append(Event("done.state." + parent.id, self._donedata(s), "internal"))
        grand = parent.parent
        if grand is not None and grand.is_parallel and all(self._in_final(c) for c in grand.substates):
            self.internal.append(Event("done.state." + grand.id, None, "internal"))

    def _in_final(self: MicrostepSession, s: CState) -> bool:
        if s.is_compound:
            return any(c.is_final and c in self._config for c in s.substates)
        if s.is_parallel:
            return all(self._in_final(c) for c in s.substates)
        return False

    def _donedata(self: MicrostepSession, s: CState) -> Any:
        if s.donedata is None:
            return None
        try:
            return self._done_data(s.donedata.evaluate(self))
        except EvaluationError as exc:
            self._error("error.execution", str(exc))
            return None

    def _entry_set(self: MicrostepSession, enabled: list[CTransition]) -> EntrySet:
        single = enabled[0] if len(enabled) == 1 else None
        if single is not None and single.entry_cache is not None:
            return single.entry_cache
        builder = EntryBuilder(self._history)
        for t in enabled:
            builder.add(t)
        result = (sorted(builder.states, key=doc_order), builder.default_entry, builder.history_content)
        if single is not None and not builder.saw_history:
            single.entry_cache = result
        return result
