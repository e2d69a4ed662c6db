"""Shared by the statechart tests: run a chart to the end against a manual clock."""

from __future__ import annotations

from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.interpreter import Interpreter

MAX_STEPS = 1_000


def run_to_end(interpreter: Interpreter, clock: ManualClock, max_steps: int = MAX_STEPS) -> Interpreter:
    """Run until the session stops or nothing is left to do; idle time jumps to the next delayed send.

    Bounded: at most ``max_steps`` macrosteps or clock jumps, never a sleep.
    """
    for _ in range(max_steps):
        if interpreter.started and not interpreter.running:
            break
        if interpreter.execute_once() is None:
            due = interpreter.next_due()
            if due is None:
                break
            clock.advance_to(due)
    return interpreter
