"""A seeded generator of long bin-picking tasks with faults injected (for the repair tests and bench/bench_repair.py)."""

from __future__ import annotations

import random
from dataclasses import replace

from plugnproduce.description.model import Step, Task

KINDS = ("move-to", "swap", "force", "absent", "dropped", "unknown")
"""Faults: a place became a move-to; a place swapped with the next bin-pick; a grip force out of
range; a robot bound to a device not in the cell; a place left out; a parameter place does not declare."""


def faulty_task(pairs: int, faults: int, seed: int, kinds: tuple[str, ...] = KINDS, varied: bool = False) -> Task:
    """``pairs`` x (bin-pick, place) with ``faults`` faults of random kinds at random places (seeded).

    ``varied``: every place gets its own speed, so that no two stretches of the task are alike."""
    rnd = random.Random(seed)
    steps = [Step(0, c) for _ in range(pairs) for c in ("bin-pick", "place")]
    if varied:
        steps = [replace(st, params={"speed": 10 + n / 1000}) if st.command == "place" else st
                 for n, st in enumerate(steps)]
    dropped = set()
    for pair in sorted(rnd.sample(range(1, pairs - 1), faults)):
        i = 2 * pair + 1  # a place
        kind = rnd.choice(kinds)
        if kind == "move-to":
            steps[i] = Step(0, "move-to")
        elif kind == "swap":
            steps[i], steps[i + 1] = steps[i + 1], steps[i]
        elif kind == "force":
            steps[i - 1] = replace(steps[i - 1], params={"grip_force": rnd.choice((0, 500))})
        elif kind == "absent":
            steps[i] = replace(steps[i], bind={"robot": "scara"})
        elif kind == "dropped":
            dropped.add(i)
        else:
            steps[i] = replace(steps[i], params={"grip_force": 40})
    kept = [st for n, st in enumerate(steps) if n not in dropped]
    return Task("long", tuple(replace(st, index=n) for n, st in enumerate(kept, start=1)), "long.yaml")
