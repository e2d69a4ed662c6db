"""Benchmark of the executor end to end (prints figures; not a test).

    python bench/bench_run.py [--runs 3]

Runs the bin-picking task (three picks and places) on the simulated cell, over XIRP and
UPnP on loopback, and splits each cycle (one bin-pick and one place) from its journal into
device time (some device is busy: from a command to that device's next event) and
controller overhead (no device is busy: the controller is reacting, generating the next
command, or waiting on the network).
"""

from __future__ import annotations

import argparse
import asyncio
import atexit
import os
import statistics
import tempfile
import time
from pathlib import Path

from plugnproduce import controller, service
from plugnproduce.executor.journal import read_journal


def busy_time(records: list[dict[str, object]]) -> float:
    """Length of the union of the intervals in which a device works on a command."""
    intervals: list[tuple[float, float]] = []
    waiting: dict[object, float] = {}
    for r in records:
        if r["kind"] == "command":
            waiting.setdefault(r["device"], float(r["t"]))  # type: ignore[arg-type]
        elif r["kind"] == "event" and r["device"] in waiting:
            intervals.append((waiting.pop(r["device"]), float(r["t"])))  # type: ignore[arg-type]
    total, end = 0.0, float("-inf")
    for a, b in sorted(intervals):
        if b > end:
            total += b - max(a, end)
            end = b
    return total


def cycles(records: list[dict[str, object]]) -> list[tuple[float, float]]:
    """Per cycle (steps 1-2, 3-4, 5-6): wall time and device time."""
    starts = [float(r["t"]) for r in records if r["kind"] == "step"]  # type: ignore[arg-type]
    end = float(records[-1]["t"])  # type: ignore[arg-type]
    bounds = [*starts[::2], end]
    out = []
    for a, b in zip(bounds, bounds[1:], strict=False):
        part = [r for r in records if a <= float(r["t"]) < b]  # type: ignore[arg-type]
        out.append((b - a, busy_time(part)))
    return out


async def main(runs: int) -> None:
    task, cell = service.builtin("tasks", "bin-picking.yaml"), service.builtin("cells", "bin-picking.yaml")
    walls, devices = [], []
    started, started_cpu = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory() as folder:
        for i in range(runs):
            report = await controller.run_task(task, cell, simulate=True, journal=Path(folder) / f"run{i}.jsonl")
            assert report.outcome == "succeeded", report.fault
            for wall, busy in cycles(read_journal(report.journal).records):
                walls.append(wall)
                devices.append(busy)
    wall, cpu = time.perf_counter() - started, time.process_time() - started_cpu
    overhead = [w - d for w, d in zip(walls, devices, strict=True)]
    print(f"bin-pick + place cycle on the simulated cell, {len(walls)} cycles: "
          f"median {1000 * statistics.median(walls):.0f} ms = device time {1000 * statistics.median(devices):.0f} ms"
          f" + controller overhead {1000 * statistics.median(overhead):.1f} ms "
          f"({100 * statistics.median(overhead) / statistics.median(walls):.1f} %)")
    print(f"{runs} runs (check, generation, devices and controller in this process): wall {wall:.2f} s, "
          f"CPU {cpu:.2f} s = {100 * cpu / wall:.0f} % of the wall time; the controller's own CPU apart: "
          "bench/bench_overhead.py")


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3)
    asyncio.run(main(parser.parse_args().runs))
