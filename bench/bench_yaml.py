"""Benchmark of task YAML loading (prints figures; not a test).

    python bench/bench_yaml.py [--steps 1000] [--rounds 5]

A long task (the bin-picking task's steps repeated) loaded with ``load_task``: events
from libyaml's C parser against the pure-Python parser, and the pure-Python
``yaml.compose`` the loader used before, all in the same run.
"""

from __future__ import annotations

import argparse
import atexit
import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import yaml

from plugnproduce import safeio
from plugnproduce.description.loader import load_task

TASK = Path(__file__).resolve().parents[1] / "descriptions" / "tasks" / "bin-picking.yaml"


def _best(rounds: int, work: Callable[[], object]) -> tuple[float, float]:
    """The shortest wall time and the shortest CPU time (user+sys of this process) of ``rounds`` runs."""
    walls, cpus = [], []
    for _ in range(rounds):
        start, start_cpu = time.perf_counter(), time.process_time()
        work()
        cpus.append(time.process_time() - start_cpu)
        walls.append(time.perf_counter() - start)
    return min(walls), max(min(cpus), 1e-9)


def main(steps: int, rounds: int) -> None:
    head, body = TASK.read_text(encoding="utf-8").split("steps:\n")
    per_copy = body.count("- command:")
    text = "task: long\nsteps:\n" + body * max(1, steps // per_copy)
    n = text.count("- command:")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "long.yaml"
        path.write_text(text, encoding="utf-8")
        fast = _best(rounds, lambda: load_task(path))
        safeio._YAML_LOADER = yaml.SafeLoader  # the pure-Python parser under the same composer
        slow = _best(rounds, lambda: load_task(path))
        safeio._YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
        compose = _best(rounds, lambda: yaml.compose(text, Loader=yaml.SafeLoader))
    print(f"{n}-step task, best of {rounds} (wall | CPU):")
    print(f"  load_task, libyaml events      {1000 * fast[0] / n:6.3f} | {1000 * fast[1] / n:6.3f} ms per step")
    print(f"  load_task, pure-Python events  {1000 * slow[0] / n:6.3f} | {1000 * slow[1] / n:6.3f} ms per step = "
          f"{slow[0] / fast[0]:.1f}× | {slow[1] / fast[1]:.1f}× libyaml")
    print(f"  yaml.compose alone, pure Python {1000 * compose[0] / n:6.3f} | {1000 * compose[1] / n:6.3f} ms per step "
          f"= {compose[0] / fast[0]:.1f}× | {compose[1] / fast[1]:.1f}× the whole libyaml load_task")


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--rounds", type=int, default=5)
    options = parser.parse_args()
    main(options.steps, options.rounds)
