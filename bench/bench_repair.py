"""Benchmark of repair window by window against the whole-task optimum (prints figures; not a test).

    python bench/bench_repair.py [--seed 1] [--whole-up-to 1000] [--processes [--rounds 3]] [--phases]

Long bin-picking tasks with faults injected (``tests/reasoning/faulty_tasks.py``, seeded): 100,
1,000, 2,000 and 10,000 steps with one fault per 100 steps, every place with its own speed so that
no two windows are alike, repaired window by window; the whole-task solver of the same run repairs
those of at most ``--whole-up-to`` steps too, and its optimal cost must equal the windowed one.
Then the same with repeated steps (windows alike are solved once), and 200-step repairs with the
built-in catalogue.
Targets: 1,000 steps < 2 s, 10,000 steps < 30 s, time per step roughly flat; catalogue < 2 s.
``--processes``: ``pnp repair`` against ``pnp check`` of the same task as whole processes (CPU time, paired
rounds, with a cache folder of their own); ``--phases``: where ``pnp repair`` of the 10,000-step task spends
its CPU time.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # the checkout's tests/ (the task generator)

from plugnproduce import service  # noqa: E402
from plugnproduce.description.model import Cell, DeviceDescription, Task  # noqa: E402
from plugnproduce.reasoning import Repair  # noqa: E402
from plugnproduce.reasoning.repairs import repairs, windows  # noqa: E402
from tests.reasoning.faulty_tasks import faulty_task  # noqa: E402

K = service.knowledge()
Solver = Callable[..., list[Repair]]


def timed(solve: Solver, task: Task, cell: Cell, catalogue: list[DeviceDescription] | None) -> tuple[float, Repair]:
    """Seconds and best repair of one solve."""
    t = time.perf_counter()
    best = solve(task, cell, K, catalogue, top=1)[0]
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


def _process(args: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU seconds (user+sys) of a command run as a process."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu, t = usage.ru_utime + usage.ru_stime, time.perf_counter()
    subprocess.run([sys.executable, *args], capture_output=True, check=False, env=env)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.perf_counter() - t, usage.ru_utime + usage.ru_stime - cpu


def processes(seed: int, rounds: int) -> None:
    """``pnp repair`` against ``pnp check`` of the same task, both as processes (targets: 1,000 steps with 10
    faults within a check + 2 s of CPU; 10,000 steps with 100 faults at most 2x a check), in paired rounds.

    Both run with a cache folder of their own (``XDG_CACHE_HOME``), warmed by one run of each that is not
    counted: the user's cache keeps only the last few task files, knowledges and devices, so other users of the
    machine would evict warm entries between rounds and decide the figures."""
    cell = str(service.builtin("cells", "bin-picking.yaml"))
    with tempfile.TemporaryDirectory(prefix="pnp-bench-repair-") as tmp:
        env = {**os.environ, "XDG_CACHE_HOME": str(Path(tmp) / "cache")}
        print(f"as processes: a cache folder of their own (XDG_CACHE_HOME={env['XDG_CACHE_HOME']}), warmed by "
              f"one uncounted run of each command", flush=True)
        for steps, target in ((1000, "check + 2 s"), (10000, "2x check")):
            path = Path(tmp) / f"faulty-{steps}.yaml"
            path.write_text(service.task_text(faulty_task(steps // 2, steps // 100, seed, varied=True), block=True),
                            encoding="utf-8")
            names = ("check", "repair")
            for name in names:  # warm the private cache: the task file read, the knowledge, the devices
                _process(["-m", "plugnproduce", name, str(path), "--cell", cell], env)
            runs: dict[str, list[tuple[float, float]]] = {name: [] for name in names}
            load = [os.getloadavg()[0]]
            for _ in range(rounds):
                for name in names:
                    runs[name].append(_process(["-m", "plugnproduce", name, str(path), "--cell", cell], env))
                load.append(os.getloadavg()[0])
            _report(steps, target, runs, load)


def _report(steps: int, target: str, runs: dict[str, list[tuple[float, float]]], load: list[float]) -> None:
    """One line per size: medians of CPU and wall time, and the CPU ratio of each paired round."""
    check = [statistics.median(r[i] for r in runs["check"]) for i in (0, 1)]
    repair = [statistics.median(r[i] for r in runs["repair"]) for i in (0, 1)]
    ratios = [r[1] / c[1] for c, r in zip(runs["check"], runs["repair"], strict=True)]
    print(f"as processes, {steps:,} steps, {steps // 100} faults (median of {len(ratios)}, load "
          f"{min(load):.1f}-{max(load):.1f}): pnp check {check[1]:.2f} s CPU ({check[0]:.2f} s wall), "
          f"pnp repair {repair[1]:.2f} s CPU ({repair[0]:.2f} s wall): repair - check = "
          f"{repair[1] - check[1]:+.2f} s CPU, repair / check = {repair[1] / check[1]:.2f}x; per round "
          f"{', '.join(f'{x:.2f}x' for x in ratios)} (target {target})", flush=True)


def phases(seed: int) -> None:
    """Where ``pnp repair`` of the 10,000-step task spends its CPU time, step by step as the command takes them
    (in this process, after start-up: reading the task, its check, the windows, checking the three repairs
    again with their side effects, their cycle times, writing them)."""
    from plugnproduce.reasoning.repairs.sideeffects import assess
    from plugnproduce.statechart import gcpause

    cell_path = service.builtin("cells", "bin-picking.yaml")
    with tempfile.TemporaryDirectory(prefix="pnp-bench-repair-") as tmp:
        path = Path(tmp) / "faulty-10000.yaml"
        path.write_text(service.task_text(faulty_task(5000, 100, seed, varied=True), block=True), encoding="utf-8")
        cell = service.cell(cell_path)
        laps: list[tuple[str, float]] = []

        def lap(what: str, since: list[float] = [time.process_time()]) -> None:  # noqa: B006
            now = time.process_time()
            laps.append((what, now - since[0]))
            since[0] = now

        task = service.task(path)
        lap("read the task")
        checked = service.check(task, cell, K)
        lap("check it")
        with gcpause.paused():  # as service.assessed_repairs makes them
            found = service.repair(task, cell, None, 3, knowledge=K)
            lap("repair it window by window (3 best)")
            assessed = assess(found, task, cell, K, (), checked)
            lap("check the repairs again, their side effects")
        service.repair_cycle_times(assessed, cell, None, K)
        lap("their cycle times")
        for r in assessed:
            service.task_text(r.repair.task)
        lap("write the repaired tasks")
    total = sum(s for _, s in laps)
    print("pnp repair, 10,000 steps, 100 faults, in-process CPU time after start-up:")
    for what, seconds in laps:
        print(f"  {what:45s} {seconds:6.2f} s ({100 * seconds / total:4.1f} %)")


def main() -> None:
    """Run the benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--whole-up-to", type=int, default=1000, help="largest task the whole-task solver repairs")
    parser.add_argument("--processes", action="store_true", help="only pnp repair against pnp check, as processes")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--phases", action="store_true", help="only where pnp repair of 10,000 steps spends its time")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if args.processes or args.phases:
        if args.processes:
            processes(args.seed, args.rounds)
        if args.phases:
            phases(args.seed)
        return
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    catalogue = service.catalogue()
    windows.windowed_repair(faulty_task(30, 2, args.seed), cell, K, catalogue)  # warm up
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
