"""Benchmark of start-up (prints figures; not a test).

    python bench/bench_startup.py [--rounds 7] [--slowest 12]

CPU time (user+sys of the child, ``resource.getrusage(RUSAGE_CHILDREN)``) and wall time of
``pnp --help``, importing the reasoning layer (which loads none of its parts until used), ``pnp validate`` of a
device, a warm ``pnp capabilities`` on the bin-picking
cell and ``pnp check`` of the bin-picking task (warm: the help, units, taxonomy and loaded knowledge kept in a
cache folder of the bench's own by a first run), each against a bare ``python -c pass``
measured in the same run, interleaved (so a burst of load hits every command alike). Targets,
in CPU time: ``--help`` ≤ 3×, warm ``capabilities`` ≤ 10×, ``check`` ≤ 15× ``python -c pass``.
The commands run as ``python -m plugnproduce`` with the interpreter running this script, so no
shell wrapper is counted. Then the slowest imports of each command, from ``python -X importtime``
(cumulative, top level packages only).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CELL = ROOT / "descriptions" / "cells" / "bin-picking.yaml"
TASK = ROOT / "descriptions" / "tasks" / "bin-picking.yaml"
DEVICE = ROOT / "descriptions" / "devices" / "gripper.ttl"
COMMANDS: dict[str, list[str]] = {
    "python -c pass": ["-c", "pass"],
    "pnp --help": ["-m", "plugnproduce", "--help"],
    "import reasoning": ["-c", "import plugnproduce.reasoning"],
    "pnp validate DEVICE": ["-m", "plugnproduce", "validate", str(DEVICE)],
    "pnp capabilities (warm)": ["-m", "plugnproduce", "capabilities", "--cell", str(CELL)],
    "pnp check bin-picking": ["-m", "plugnproduce", "check", str(TASK), "--cell", str(CELL)],
}
TARGETS = {"pnp --help": 3.0, "pnp capabilities (warm)": 10.0, "pnp check bin-picking": 15.0}
"""Most CPU time, as a multiple of ``python -c pass``'s."""


CACHE = tempfile.mkdtemp(prefix="pnp-bench-cache-")
"""The cache folder of the measured commands: their own, so that warm means kept by this bench's first run, not
left or evicted by whatever else runs as the same user (each kind of kept file is bounded in number)."""


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # warm means as installed: byte code written once, then read
    env["XDG_CACHE_HOME"] = CACHE
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), env.get("PYTHONPATH", "")) if p)
    return env


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def once(args: list[str], extra: tuple[str, ...] = ()) -> tuple[float, float, str]:
    """Wall and CPU seconds of one run, and its stderr."""
    cpu, start = _children_cpu(), time.perf_counter()
    done = subprocess.run([sys.executable, *extra, *args], env=_env(), capture_output=True, text=True, check=False)
    if done.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(args)}: exit {done.returncode}: {done.stderr.strip()[-300:]}")
    return time.perf_counter() - start, _children_cpu() - cpu, done.stderr


def slowest_imports(args: list[str], top: int) -> list[tuple[float, str]]:
    """The ``top`` top-level imports with the largest cumulative time (seconds, name)."""
    *_, err = once(args, ("-X", "importtime"))
    rows = []
    for line in err.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        _, cumulative, name = line.split("|")
        if cumulative.strip().isdigit() and not name.startswith("  "):  # top level only: no double counting
            rows.append((int(cumulative) / 1e6, name.strip()))
    return sorted(rows, reverse=True)[:top]


def main(rounds: int, top: int) -> None:
    for args in COMMANDS.values():
        once(args)  # warm: byte code, the taxonomy and unit caches written
    wall: dict[str, list[float]] = {name: [] for name in COMMANDS}
    cpu: dict[str, list[float]] = {name: [] for name in COMMANDS}
    load = [os.getloadavg()[0]]
    for _ in range(rounds):
        for name, args in COMMANDS.items():
            w, c, _ = once(args)
            wall[name].append(w)
            cpu[name].append(c)
        load.append(os.getloadavg()[0])
    base_cpu, base_wall = statistics.median(cpu["python -c pass"]), statistics.median(wall["python -c pass"])
    print(f"median of {rounds} interleaved runs each; load average {min(load):.2f}-{max(load):.2f} "
          f"on {os.cpu_count()} cores")
    print(f"  {'command':<26} {'CPU s':>7} {'× pass':>7} {'wall s':>7} {'× pass':>7}  target (CPU)")
    for name in COMMANDS:
        c, w = statistics.median(cpu[name]), statistics.median(wall[name])
        target = TARGETS.get(name)
        verdict = "" if target is None else f"≤ {target:g}×  {'met' if c / base_cpu <= target else 'NOT MET'}"
        print(f"  {name:<26} {c:7.3f} {c / base_cpu:6.1f}× {w:7.3f} {w / base_wall:6.1f}×  {verdict}")
    for name in ("pnp --help", "pnp capabilities (warm)", "pnp check bin-picking"):
        print(f"slowest imports of {name} (cumulative, top-level):")
        for seconds, module in slowest_imports(COMMANDS[name], top):
            print(f"  {1000 * seconds:7.1f} ms  {module}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--slowest", type=int, default=12)
    options = parser.parse_args()
    try:
        main(options.rounds, options.slowest)
    finally:
        shutil.rmtree(CACHE, ignore_errors=True)
