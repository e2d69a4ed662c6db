"""Benchmark of code generation for long tasks (prints figures; not a test).

    python bench/bench_generate.py [--steps 100 1000 10000] [--repeat 3] [--tasks repeated distinct]

For each size, bin-picking tasks of that many steps on the built-in bin-picking cell:
``repeated`` (ten steps of bin-pick/place written out, repeated) and ``distinct`` (every
step written out, each with its own grip force or speed, so no two steps are the same):

- **baseline**: reading the task and writing its expanded steps as JSON, one line per step
  (what any tool that touches every step pays);
- **check**: the reasoner's plausibility check and role bindings;
- **generate**: the charts built (specific, task, closed-world, device programs) and written to a folder;
- **bytes/step**: per chart kind, the bytes written divided by the number of steps, and the
  files written; every file must stay within the input limit of ``pnp validate``
  (``plugnproduce.safeio.MAX_BYTES``), and all are validated at the end.

Targets: generation of 10,000 steps under 10 s; under 1 KB per step per chart.
Each time is the best of ``--repeat`` measurements.
"""

from __future__ import annotations

import argparse
import atexit
import json
import os
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path

from plugnproduce import service
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.outputs import all_charts
from plugnproduce.resources import descriptions_path
from plugnproduce.safeio import MAX_BYTES
from plugnproduce.validation.validate import validate_paths

CYCLE = 10
"""Steps written out in the task file; ``repeat`` makes up the rest."""


def task_file(folder: Path, steps: int, kind: str) -> Path:
    """A bin-picking task of ``steps`` steps: ten written out and repeated, or all written out and distinct."""
    text = (descriptions_path() / "tasks" / "bin-picking.yaml").read_text(encoding="utf-8")
    head, body = text.split("steps:\n")
    path = folder / f"bin-picking-{kind}-{steps}.yaml"
    if kind == "distinct":
        cycles = (body.replace("grip_force: 45", f"grip_force: {20 + i % 50}").replace("speed: 80", f"speed: {i + 1}")
                  for i in range(steps // 2))
        path.write_text(head.replace("repeat: 3", "repeat: 1") + "steps:\n" + "".join(cycles), encoding="utf-8")
        return path
    cycle = min(steps, CYCLE)
    path.write_text(head.replace("repeat: 3", f"repeat: {steps // cycle}") + "steps:\n" + body * (cycle // 2),
                    encoding="utf-8")
    return path


def best(repeat: int, work: Callable[[], object]) -> tuple[float, object]:
    """The shortest of ``repeat`` timings of ``work`` and its last result; the shortest CPU time (user+sys of
    this process) of the same runs is kept in :data:`CPU` under the work's name."""
    times, cpus, result = [], [], None
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        result = work()
        cpus.append(time.process_time() - start_cpu)
        times.append(time.perf_counter() - start)
    CPU[getattr(work, "__name__", "work")] = max(min(cpus), 1e-9)
    return min(times), result


CPU: dict[str, float] = {}
"""The last CPU time :func:`best` measured, by the name of the work."""


def measure(steps: int, kind: str, repeat: int, folder: Path) -> None:
    """Print the figures for a task of ``steps`` steps."""
    path = task_file(folder, steps, kind)
    cell = service.cell(descriptions_path() / "cells" / "bin-picking.yaml")
    knowledge = service.knowledge()
    processes = {p.id: p for p in knowledge.processes}

    def baseline() -> int:
        task = service.task(path)
        lines = [json.dumps({"command": s.command, "bind": s.bind, "params": s.params}) for s in task.steps]
        out = folder / "baseline.jsonl"
        out.write_text("\n".join(lines), encoding="utf-8")
        return out.stat().st_size

    t_base, base_bytes = best(repeat, baseline)
    task = service.task(path)
    def check() -> object:
        return service.check(task, cell)

    t_check, result = best(repeat, check)
    bindings = result.bindings()  # type: ignore[attr-defined]
    out = folder / f"out-{kind}-{steps}"
    out.mkdir(exist_ok=True)

    def generate() -> list[Path]:
        generated = generate_task(task, cell, bindings, processes, knowledge.taxonomy)
        written = []
        for chart in all_charts(generated, cell, per_device=True):
            (out / chart.name).write_bytes(chart.data)
            written.append(out / chart.name)
        return written

    t_gen, files = best(repeat, generate)
    by_kind: dict[str, list[int]] = defaultdict(list)
    for f in files:  # type: ignore[attr-defined]
        by_kind["specific" if f.name.startswith("step") else f.name.split(".")[-2]].append(f.stat().st_size)
    print(f"{steps:>6} steps {kind:<9} baseline {t_base:7.3f} s {base_bytes / steps:6.1f} B/step | "
          f"check {t_check:7.3f} s | generate {t_gen:7.3f} s ({t_gen / t_base:5.1f}x baseline) | CPU: baseline "
          f"{CPU['baseline']:7.3f} s, check {CPU['check']:7.3f} s, generate {CPU['generate']:7.3f} s "
          f"({CPU['generate'] / CPU['baseline']:5.1f}x baseline)")
    for chart_kind, sizes in sorted(by_kind.items()):
        print(f"{'':>24}{chart_kind:<13} {len(sizes):>3} file(s) {sum(sizes) / steps:8.1f} B/step  "
              f"largest {max(sizes):>9} B  within validate's limit: {max(sizes) <= MAX_BYTES}")
    report = validate_paths(files)  # type: ignore[arg-type]
    print(f"{'':>24}pnp validate: {'valid' if report.valid else 'NOT VALID'} ({len(files)} files)")  # type: ignore[arg-type]


def main() -> None:
    """Run the benchmark and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, nargs="+", default=[100, 1000, 10000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--tasks", nargs="+", choices=("repeated", "distinct"), default=["repeated", "distinct"])
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-generate-") as tmp:
        for steps in args.steps:
            for kind in args.tasks:
                measure(steps, kind, args.repeat, Path(tmp))


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    main()
