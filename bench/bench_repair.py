"""Benchmark of repair window by window against the whole-task optimum (prints figures; not a test).

    python bench/bench_repair.py [--seed 1] [--whole-up-to 1000]

Long bin-picking tasks with faults injected (``tests/reasoning/faulty_tasks.py``, seeded): 100,
1,000, 2,000 and 10,000 steps with one fault per 100 steps, every place with its own speed so that
no two windows are alike, repaired window by window; the whole-task solver of the same run repairs
those of at most ``--whole-up-to`` steps too, and its optimal cost must equal the windowed one.
Then the same with repeated steps (windows alike are solved once), and 200-step repairs with the
built-in catalogue.
Targets: 1,000 steps < 2 s, 10,000 steps < 30 s, time per step roughly flat; catalogue < 2 s.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # the checkout's tests/ (the task generator)

from plugnproduce import service  # noqa: E402
from plugnproduce.description.model import Cell, DeviceDescription, Task  # noqa: E402
from plugnproduce.reasoning import Repair, repairs, windows  # noqa: E402
from tests.reasoning.faulty_tasks import faulty_task  # noqa: E402

K = service.knowledge()
Solver = Callable[..., list[Repair]]


def timed(solve: Solver, task: Task, cell: Cell, catalogue: list[DeviceDescription] | None) -> tuple[float, Repair]:
    """Seconds and best repair of one solve."""
    t = time.perf_counter()
    best = solve(task, cell, K.taxonomy, K.processes, catalogue, top=1)[0]
    return time.perf_counter() - t, best


def compare(task: Task, cell: Cell, catalogue: list[DeviceDescription] | None, whole: bool, what: str) -> float:
    """Print windowed (and whole-task) time and cost; return the windowed seconds."""
    dt, best = timed(windows.windowed_repair, task, cell, catalogue)
    bought = tuple(d for d in catalogue or () if d.id in best.added_devices)
    plausible = service.check(best.task, Cell(cell.name, cell.devices + bought, cell.file)).plausible
    line = (f"repair, {what}: windowed {dt:.2f} s ({1e3 * dt / len(task.steps):.2f} ms/step), cost {best.cost:g}, "
            f"{len(best.edits)} edits, plausible after: {plausible}")
    if whole:
        wt, wbest = timed(repairs.repair, task, cell, catalogue)
        same = "same cost" if wbest.cost == best.cost else f"DIFFERENT cost {wbest.cost:g}"
        line += f"; whole-task {wt:.2f} s, {same}; ratio whole/windowed {wt / dt:.1f}x"
    print(line, flush=True)
    return dt


def main() -> None:
    """Run the benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--whole-up-to", type=int, default=1000, help="largest task the whole-task solver repairs")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    catalogue = service.catalogue()
    windows.windowed_repair(faulty_task(30, 2, args.seed), cell, K.taxonomy, K.processes, catalogue)  # warm up
    per_step = {}
    for steps in (100, 1000, 2000, 10000):
        task = faulty_task(steps // 2, steps // 100, args.seed, varied=True)
        target = {1000: " (target < 2 s)", 10000: " (target < 30 s)"}.get(steps, "")
        what = f"{steps:,} steps, {steps // 100} faults, no two windows alike{target}"
        per_step[steps] = compare(task, cell, None, steps <= args.whole_up_to, what) / len(task.steps)
    print(f"time per step, 10,000 against 1,000 steps: {per_step[10000] / per_step[1000]:.2f}x (linear: 1x)")
    for steps in (1000, 10000):  # a repeated task: windows alike are solved once
        task = faulty_task(steps // 2, steps // 100, args.seed)
        compare(task, cell, None, False, f"{steps:,} steps, {steps // 100} faults, repeated steps")
    for varied in (True, False):
        task = faulty_task(100, 10, args.seed, varied=varied)
        what = "no two windows alike" if varied else "repeated steps"
        compare(task, cell, catalogue, True, f"200 steps, 10 faults, {what}, built-in catalogue (target < 2 s)")


if __name__ == "__main__":
    main()
