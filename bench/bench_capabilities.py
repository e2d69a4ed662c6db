"""Benchmark of offered commands on big cells (prints figures; not a test).

    python bench/bench_capabilities.py [--runs 20]

Cells of 10, 100 and 1,000 devices (copies of the built-in catalogue's devices under new ids),
all built-in processes. For each: the warm median time of ``capabilities`` (one binding per
offered command, their number, the devices per role), and, where the bindings can be listed,
today's enumeration of every binding (``all_bindings=True``) in the same run: the ratio between
them, and a check that both give the same offered commands, reasons, counts and first binding.
Targets: 100 devices < 100 ms; time growing no worse than linearly in the number of devices.
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import time
from collections.abc import Callable
from dataclasses import replace

from plugnproduce import service
from plugnproduce.description.model import Cell
from plugnproduce.reasoning import Capabilities

LISTABLE = 1_000_000
"""Enumerate every binding only up to this many."""


def big_cell(n: int) -> Cell:
    """``n`` devices: the catalogue's devices over and over, each copy with its own id."""
    devices = itertools.cycle(service.catalogue())
    return Cell(f"big-{n}", tuple(replace(d, id=f"{d.id}-{k}") for k, d in zip(range(n), devices, strict=False)))


def median_time(call: Callable[[], Capabilities], runs: int) -> tuple[float, Capabilities, float]:
    """Warm median seconds of ``call`` over ``runs`` runs, its answer, and its median CPU seconds (user+sys of
    this process)."""
    answer = call()
    times, cpus = [], []
    for _ in range(runs):
        t, c = time.perf_counter(), time.process_time()
        call()
        cpus.append(time.process_time() - c)
        times.append(time.perf_counter() - t)
    return statistics.median(times), answer, max(statistics.median(cpus), 1e-9)


def same(few: Capabilities, every: Capabilities) -> bool:
    """Whether the default answer agrees with the one listing every binding."""
    return (few.commands() == every.commands() and few.not_offered == every.not_offered
            and all(a.binding_count == len(b.bindings) and a.bindings == b.bindings[:1]
                    for a, b in zip(few.offered, every.offered, strict=True)))


def main() -> None:
    """Run the benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--runs", type=int, default=20)
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    per_device, cpu_per_device = {}, {}
    for n in (10, 100, 1000):
        cell = big_cell(n)
        dt, caps, cpu = median_time(lambda c=cell: service.capabilities(c), args.runs if n < 1000 else 5)
        count = sum(o.binding_count for o in caps.offered)
        size = len(str(caps.to_json()))
        per_device[n], cpu_per_device[n] = dt / n, cpu / n
        target = " (target < 100 ms)" if n == 100 else ""
        line = (f"offered commands, {n:,} devices: {1e3 * dt:.1f} ms warm{target}, CPU {1e3 * cpu:.1f} ms; "
                f"{len(caps.offered)} offered, "
                f"{count:,} bindings counted, {size:,} characters of JSON")
        if count <= LISTABLE:
            old, every, old_cpu = median_time(lambda c=cell: service.capabilities(c, all_bindings=True), 3)
            line += (f"; listing every binding {1e3 * old:.1f} ms ({len(str(every.to_json())):,} characters), "
                     f"ratio {old / dt:.1f}x, CPU {old_cpu / cpu:.1f}x, same answers: {same(caps, every)}")
        else:
            line += "; listing every binding not run (too many)"
        print(line, flush=True)
    print(f"time per device, 1,000 against 100 devices: {per_device[1000] / per_device[100]:.2f}x "
          f"(no worse than linear: <= 1x), CPU {cpu_per_device[1000] / cpu_per_device[100]:.2f}x; 100 against 10: "
          f"{per_device[100] / per_device[10]:.2f}x, CPU {cpu_per_device[100] / cpu_per_device[10]:.2f}x")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
