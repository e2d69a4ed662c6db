"""Keep the cyclic garbage collector off large compiled charts while they are built and run.

Python's collector walks every tracked object on each full collection. A compiled
closed-world chart of a thousand steps is about half a million objects, so one full
collection in the middle of a run costs more than thousands of events, and the cost
per event grows with the chart. While a large chart runs, the objects alive when it
was compiled (the chart, and whatever long-lived data the program holds) are frozen
(:func:`gc.freeze`): reference counting still frees them, the collector no longer
walks them. When the last such session ends they are unfrozen, so cyclic garbage of
that time is collected as usual and nothing leaks. While a chart is compiled, automatic
collection pauses: compiling makes no garbage, only objects that live as long as the chart.
"""

from __future__ import annotations

import gc
import threading

LARGE_CHART = 200
"""Compiled states and transitions from which a session freezes the collector's view.

Generated charts are above it (a 10-step closed world compiles to about 350); device
models (at most a few dozen), which a simulation runs for as long as it lives, are below,
so they never keep old garbage frozen. Below it, a full collection walks the program's
other long-lived objects (the ontology, the reasoner's data) and costs a small chart as
much per event as it would cost a large one."""

_lock = threading.Lock()
_holders = 0


def hold() -> None:
    """A large chart starts a session: freeze what is alive now (again, if others already hold)."""
    global _holders
    with _lock:
        _holders += 1
        gc.freeze()


def release() -> None:
    """A session that held ends; the last one to end unfreezes everything frozen."""
    global _holders
    with _lock:
        if _holders == 0:
            return
        _holders -= 1
        if _holders == 0:
            gc.unfreeze()


def holders() -> int:
    """How many sessions hold the collector's view frozen now."""
    return _holders
