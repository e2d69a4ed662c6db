"""Benchmark of start-up (prints figures; not a test).

    python bench/bench_startup.py [--rounds 7] [--slowest 15]

Wall time of ``pnp --help`` and of a warm ``pnp capabilities`` on the bin-picking cell,
each against a bare ``python -c pass`` measured in the same run (targets on an idle
2-core machine: under 0.2 s and 0.5 s). The commands run as ``python -m plugnproduce``
with the interpreter running this script, so no shell wrapper is counted. Then the
slowest imports of each command, from ``python -X importtime`` (cumulative, top level
packages only).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CELL = ROOT / "descriptions" / "cells" / "bin-picking.yaml"
COMMANDS: dict[str, list[str]] = {
    "python -c pass": ["-c", "pass"],
    "pnp --help": ["-m", "plugnproduce", "--help"],
    "pnp capabilities (warm)": ["-m", "plugnproduce", "capabilities", "--cell", str(CELL)],
}
TARGETS = {"pnp --help": 0.2, "pnp capabilities (warm)": 0.5}


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), env.get("PYTHONPATH", "")) if p)
    return env


def _once(args: list[str], extra: tuple[str, ...] = ()) -> tuple[float, str]:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, *extra, *args], env=_env(), capture_output=True, text=True, check=True)
    return time.perf_counter() - start, done.stderr


def slowest_imports(args: list[str], top: int) -> list[tuple[float, str]]:
    """The ``top`` top-level imports with the largest cumulative time (seconds, name)."""
    _, err = _once(args, ("-X", "importtime"))
    rows = []
    for line in err.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        _, cumulative, name = line.split("|")
        if cumulative.strip().isdigit() and not name.startswith("  "):  # top level only: no double counting
            rows.append((int(cumulative) / 1e6, name.strip()))
    return sorted(rows, reverse=True)[:top]


def main(rounds: int, top: int) -> None:
    _once(COMMANDS["pnp capabilities (warm)"])  # warm: byte code and the taxonomy cache written
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for _ in range(rounds):  # interleaved, so a burst of load hits every command alike
        for name, args in COMMANDS.items():
            times[name].append(_once(args)[0])
    base = statistics.median(times["python -c pass"])
    print(f"median of {rounds} runs each (load average now {os.getloadavg()[0]:.2f}):")
    for name, samples in times.items():
        median = statistics.median(samples)
        target = f"   target < {TARGETS[name]:.1f} s idle" if name in TARGETS else ""
        print(f"  {name:<26} {median:6.3f} s  = {median / base:5.1f}× python -c pass, "
              f"+{median - base:.3f} s{target}")
    for name in ("pnp --help", "pnp capabilities (warm)"):
        print(f"slowest imports of {name} (cumulative, top-level):")
        for seconds, module in slowest_imports(COMMANDS[name], top):
            print(f"  {1000 * seconds:7.1f} ms  {module}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--slowest", type=int, default=15)
    options = parser.parse_args()
    main(options.rounds, options.slowest)
