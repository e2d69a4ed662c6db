"""Benchmark of verification over every interleaving (prints figures; not a test).

    python bench/bench_verify.py [--steps 6 100] [--repeat 3] [--naive-limit 100000]
    python bench/bench_verify.py --growth [BOUND ...]

Two families of tasks, each of ``--steps`` steps, with the program already generated:

- ``bin-picking``: the bin-picking task (its two steps repeated) on the built-in bin-picking
  cell; every process there is a sequence, so there is one interleaving per step;
- ``adaptive``: the pick-and-place task (pick-and-place, move-to; repeated) on the test
  library's adaptive-gripper cell, whose gripper reports finger contact before it settles:
  the controller and the gripper overlap, one diamond per pick, 2^picks interleavings.

For each:

- **simulate** (baseline): one run of the closed-world chart (the task chart and the device
  models in one document) in the project's runtime, delayed sends taken in time order: one
  interleaving, the check the project made before verification. It must end in ``done``.
- **verify**: every interleaving explored (:func:`plugnproduce.verification.verify`); its
  verdict must be ``proved`` when the simulation reached ``done``. Its states and transitions
  are printed, and its time as a ratio to the simulation.
- **naive**: the same moves explored breadth-first with no visited set (every interleaving
  walked as a separate path, as a search that does not recognise a configuration it has seen);
  stopped after ``--naive-limit`` paths. Its verdict must agree when it finishes.

Each time is the best of ``--repeat`` measurements.

Then **growth** (``--growth``): the bin-picking until-empty task (localise, pick, place in a loop
until the bin is empty) with its loop bound raised so that verification explores about 10², 10³,
10⁴ and 10⁵ configurations. Each row prints the states, the wall and CPU time (user+sys of this
process) of one verification, states per CPU second, and that rate as a ratio to the smallest
size's, measured in the same run: time per state is constant when the ratio stays near 1.
"""

from __future__ import annotations

import argparse
import atexit
import os
import tempfile
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

from plugnproduce import service
from plugnproduce.codegen import GeneratedTask
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.description.model import Cell
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.verification import Budget, verify
from plugnproduce.verification.world import ClosedWorld, World

TASKS = descriptions_path() / "tasks"
FAMILIES = {
    "bin-picking": (TASKS / "bin-picking.yaml", descriptions_path() / "cells" / "bin-picking.yaml"),
    "adaptive": (TASKS / "pick-and-place.yaml", Path(__file__).parent.parent / "tests" / "data" / "libraries"
                 / "adaptive-gripper" / "cells" / "bin-picking-adaptive.yaml"),
}


def task_file(folder: Path, family: str, steps: int) -> Path:
    """The family's task (two steps) repeated to ``steps`` steps."""
    text = FAMILIES[family][0].read_text(encoding="utf-8")
    path = folder / f"{family}-{steps}.yaml"
    repeat = f"repeat: {steps // 2}\n"
    text = text.replace("repeat: 3\n", repeat) if "repeat:" in text else text.replace("steps:\n", repeat + "steps:\n")
    path.write_text(text, encoding="utf-8")
    return path


def best(repeat: int, work: Callable[[], object]) -> tuple[float, object]:
    """The shortest of ``repeat`` timings of ``work`` and its last result."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return min(times), result


def simulate(data: bytes) -> str | None:
    """One run of the closed-world chart; the final state it ends in."""
    clock = ManualClock()
    interpreter = Interpreter(parse_chart(data, "closed-world"), clock=clock)
    interpreter.start()
    while interpreter.running:
        interpreter.execute()
        due = interpreter.next_due()
        if due is None:
            break
        clock.advance_to(due)
    return interpreter.final_state


def naive(generated: GeneratedTask, cell: Cell, limit: int) -> tuple[str, int]:
    """Every path walked separately (no visited set): the verdict ("proved", "refuted", "stopped") and paths."""
    world = ClosedWorld(generated, cell)
    start, violation = world.start()
    frontier: deque[World] = deque([start])
    walked = 1
    while frontier:
        current = frontier.popleft()
        moves = list(world.moves(current))
        if not moves and current.controller.final_state is None:
            return "refuted", walked
        for move in moves:
            after, violation = world.apply(current, move)
            if violation is not None:
                return "refuted", walked
            walked += 1
            if walked > limit:
                return "stopped", walked
            frontier.append(after)
    return "proved", walked


def measure(family: str, steps: int, repeat: int, limit: int, folder: Path) -> None:
    """Print the figures for the family's task of ``steps`` steps."""
    path = task_file(folder, family, steps)
    cell = service.cell(FAMILIES[family][1])
    generated = service.plan_run(path, cell, service.knowledge_for_cell(FAMILIES[family][1]))
    data = closed_world_chart(generated, cell)
    t_sim, final = best(repeat, lambda: simulate(data))
    t_verify, result = best(repeat, lambda: verify(generated, cell, Budget(10_000_000, 3600)))
    verdict = getattr(result, "verdict", None)
    if (final == "done") != (verdict == "proved"):
        raise RuntimeError(f"simulation ended in {final!r} but verification answered {verdict!r}")
    t_naive, (naive_verdict, walked) = best(1, lambda: naive(generated, cell, limit))  # type: ignore[misc]
    if naive_verdict != "stopped" and naive_verdict != verdict:
        raise RuntimeError(f"naive search answered {naive_verdict!r}, verification {verdict!r}")
    print(f"{family:<11} {steps:>4} steps  simulate {t_sim * 1000:8.1f} ms (ends {final}) | "
          f"verify {t_verify * 1000:8.1f} ms "
          f"{verdict}, {result.states} states, {result.transitions} transitions "  # type: ignore[union-attr]
          f"= {t_verify / t_sim:5.1f}x simulate | naive {t_naive * 1000:8.1f} ms {naive_verdict}, {walked} paths")


UNTIL_EMPTY = TASKS / "bin-picking-until-empty.yaml"
GROWTH = (4, 42, 420, 4_200)
"""Loop bounds of the until-empty task: about 24 configurations per iteration, so 10² to 10⁵ states."""


def _until_empty(text: str, bound: int, folder: Path) -> Path:
    path = folder / f"until-empty-{bound}.yaml"
    path.write_text(text.replace("max: 100\n", f"max: {bound}\n"), encoding="utf-8")
    return path


def growth(bounds: tuple[int, ...], folder: Path) -> None:
    """Print states/s of verification of the until-empty task at each loop bound, and the ratio to the first."""
    cell_path = FAMILIES["bin-picking"][1]
    cell, knowledge = service.cell(cell_path), service.knowledge_for_cell(cell_path)
    text = UNTIL_EMPTY.read_text(encoding="utf-8")
    if "max: 100\n" not in text:
        raise SystemExit(f"{UNTIL_EMPTY.name} no longer has 'max: 100': update this benchmark")
    # once untimed: the first verification of a process pays its warm-up (imports, compiled charts)
    verify(service.plan_run(_until_empty(text, bounds[0], folder), cell, knowledge), cell, Budget(10_000_000, 3600))
    first = None
    for bound in bounds:
        generated = service.plan_run(_until_empty(text, bound, folder), cell, knowledge)
        start, start_cpu = time.perf_counter(), time.process_time()
        result = verify(generated, cell, Budget(10_000_000, 3600))
        cpu, wall = time.process_time() - start_cpu, time.perf_counter() - start
        if result.verdict != "proved":
            raise RuntimeError(f"loop bound {bound}: verification answered {result.verdict!r}")
        rate = result.states / cpu
        first = first or rate
        print(f"until-empty, loop bound {bound:>5}: {result.states:>7} states {result.transitions:>7} transitions | "
              f"wall {wall:7.2f} s CPU {cpu:7.2f} s | {rate:8,.0f} states per CPU second = {rate / first:4.2f}x "
              f"the smallest's | load {os.getloadavg()[0]:.2f}", flush=True)


def main() -> None:
    """Run the benchmark and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, nargs="+", default=[6, 100])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--naive-limit", type=int, default=100_000)
    parser.add_argument("--tasks", nargs="+", choices=sorted(FAMILIES), default=sorted(FAMILIES, reverse=True))
    parser.add_argument("--growth", type=int, nargs="*", default=None, metavar="BOUND",
                        help=f"only the growth rows, at these loop bounds (none given: {' '.join(map(str, GROWTH))})")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        if args.growth is not None:
            growth(tuple(args.growth) or GROWTH, Path(tmp))
            return
        for family in args.tasks:
            for steps in args.steps:
                measure(family, steps, args.repeat, args.naive_limit, Path(tmp))


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    main()
