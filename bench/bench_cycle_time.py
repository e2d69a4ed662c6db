"""Accuracy of the cycle-time estimate: ``pnp check``'s estimate against simulated runs.

    python bench/bench_cycle_time.py [--runs 3]

For each case (a task, its cell, a speed factor), the estimate of ``pnp check --json`` and ``--runs`` runs of ``pnp
run --sim --speed F``: each run's simulated time is its journal's span from the first ``step`` record to ``end``,
times F (as its ``start`` record says). Prints the estimate, each run, their mean, and the run's excess over the
estimate in per cent (the controller's own latency per command, which the estimate leaves out: the request's way to
the device, the event's way back, the controller's step to the next command, a timer's millisecond; about 1 ms per
XIRP and 3 ms per UPnP command on an idle machine, more on a loaded one; it grows with F, since it is real time),
and the load. Before the journal's fsync of a command ran while the command went out, it added 2 to 13 ms per
command.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUILTIN = ROOT / "descriptions"
TIMED = ROOT / "tests" / "data" / "libraries" / "timed-cell"
CASES = [
    (BUILTIN / "tasks" / "pick-and-place.yaml", BUILTIN / "cells" / "bin-picking.yaml", 0.25),
    (BUILTIN / "tasks" / "bin-picking.yaml", BUILTIN / "cells" / "bin-picking.yaml", 1.0),
    (BUILTIN / "tasks" / "bin-picking.yaml", BUILTIN / "cells" / "bin-picking.yaml", 0.25),
    (TIMED / "tasks" / "pick-place-timed.yaml", TIMED / "cells" / "timed-cell.yaml", 1.0),
    (TIMED / "tasks" / "pick-place-timed.yaml", TIMED / "cells" / "timed-cell.yaml", 4.0),
    (TIMED / "tasks" / "approach-while-opening.yaml", TIMED / "cells" / "timed-cell.yaml", 1.0),
]


def pnp(*args: str) -> str:
    result = subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                            timeout=600, check=False)
    if result.returncode != 0:
        raise SystemExit(f"pnp {' '.join(args)}: exit {result.returncode}\n{result.stdout}{result.stderr}")
    return result.stdout


def estimate(task: Path, cell: Path) -> float:
    return float(json.loads(pnp("check", str(task), "--cell", str(cell), "--json"))["cycle_time"]["total_seconds"])


def simulated(task: Path, cell: Path, speed: float, folder: Path, n: int) -> float:
    journal = folder / f"run-{n}.jsonl"
    pnp("run", str(task), "--cell", str(cell), "--sim", "--speed", str(speed), "--journal", str(journal), "--json")
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    first = next(r["t"] for r in records if r["kind"] == "step")
    end = next(r["t"] for r in records if r["kind"] == "end")
    return float((end - first) * records[0]["speed"])  # the speed factor the run's start record says


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(f"load (1/5/15 min): {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"{'task':28} {'speed':>5} {'estimate':>9} {'runs (simulated s)':>26} {'mean':>7} {'excess':>7}")
    with tempfile.TemporaryDirectory() as tmp:
        for n, (task, cell, speed) in enumerate(CASES):
            guess = estimate(task, cell)
            runs = [simulated(task, cell, speed, Path(tmp), n * 100 + i) for i in range(args.runs)]
            mean = sum(runs) / len(runs)
            print(f"{task.stem:28} {speed:5g} {guess:9.2f} {' '.join(f'{r:.2f}' for r in runs):>26} "
                  f"{mean:7.2f} {100 * (mean - guess) / guess:6.1f}%")


if __name__ == "__main__":
    main()
