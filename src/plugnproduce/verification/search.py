"""Breadth-first search over the closed world's configurations.

Each configuration is visited once (keyed by :attr:`World.key`: active states, the datamodel
the charts change, the delayed sends and the messages in transit), so the first violation
found lies at the end of a shortest trace. The search stops when its budget runs out:
the answer is then inconclusive, never a hang.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Hashable
from dataclasses import dataclass

from plugnproduce.verification.results import Budget
from plugnproduce.verification.world import ClosedWorld, Move, Violation, World


@dataclass(frozen=True)
class Found:
    """How a search ended: the moves to the violation (None: none found), counts, and the budget left."""

    moves: list[Move] | None
    violation: Violation | None
    states: int
    transitions: int
    seconds: float
    exhausted: str = ""
    """Which budget ran out ("" when the search finished)."""


def search(world: ClosedWorld, budget: Budget) -> Found:
    """Explore every configuration reachable from the start of ``world`` within ``budget``."""
    began = time.perf_counter()
    start, violation = world.start()
    parents: dict[Hashable, tuple[Hashable, Move] | None] = {start.key: None}
    if violation is not None:
        return Found([], violation, 1, 0, time.perf_counter() - began)
    frontier: deque[World] = deque([start])
    transitions = expanded = 0
    while frontier:
        current = frontier.popleft()
        expanded += 1
        if expanded % 64 == 0 and time.perf_counter() - began > budget.seconds:
            return Found(None, None, len(parents), transitions, time.perf_counter() - began,
                         f"the time budget of {budget.seconds:g} s ran out")
        moves = list(world.moves(current))
        if not moves and current.controller.final_state is None:
            return Found(_path(parents, current.key), world.deadlock(current), len(parents), transitions,
                         time.perf_counter() - began)
        for move in moves:
            after, violation = world.apply(current, move)
            transitions += 1
            if violation is not None:
                return Found(_path(parents, current.key) + [move], violation, len(parents), transitions,
                             time.perf_counter() - began)
            if after.key in parents:
                continue
            if len(parents) >= budget.max_states:
                return Found(None, None, len(parents), transitions, time.perf_counter() - began,
                             f"the budget of {budget.max_states} states ran out")
            parents[after.key] = (current.key, move)
            frontier.append(after)
    return Found(None, None, len(parents), transitions, time.perf_counter() - began)


def _path(parents: dict[Hashable, tuple[Hashable, Move] | None], key: Hashable) -> list[Move]:
    moves: list[Move] = []
    while (link := parents[key]) is not None:
        key, move = link
        moves.append(move)
    return moves[::-1]
