"""Benchmark of the controller's own CPU per step in a simulated run (prints figures; not a test).

    python bench/bench_overhead.py [--runs 3] [--parts 20]

The simulated devices run in another process (``pnp sim up CELL`` on a private SSDP port), so
this process is the controller alone: discovery, the task chart's session, XIRP and UPnP
clients, the journal. For each run it measures, from the moment the run starts (after the
check and the code generation) to its end:

- the controller's CPU time (user+sys of this process, ``time.process_time``);
- the devices' busy time: the union of the intervals in which some device works on a command
  (from a command to that device's next event, read from the run's journal);
- the devices' process CPU time over the same run (``/proc/PID/stat``), for reference;
- the share of the run's wall time in which no device was busy (the cell waiting on the
  controller, the network or the machine's load), for reference: wall time, so load moves it.

Two tasks on the built-in bin-picking cell: ``bin-picking`` (three bin-picks and places) and
``until-empty`` (localise, pick and place until a simulated bin of ``--parts`` parts is empty).
Printed per task: controller CPU per step, and as a share of the devices' busy time (target
≤ 5 %), with the load average. The share is a ratio of two figures of the same run.
"""

from __future__ import annotations

import argparse
import asyncio
import atexit
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from plugnproduce import controller, service
from plugnproduce.executor.journal import read_journal

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).parent))
from bench_run import busy_time  # noqa: E402

CELL = ROOT / "descriptions" / "cells" / "bin-picking.yaml"
TASKS = {"bin-picking": ROOT / "descriptions" / "tasks" / "bin-picking.yaml",
         "until-empty": ROOT / "descriptions" / "tasks" / "bin-picking-until-empty.yaml"}
TARGET = 0.05
READY_SECONDS = 120.0


def _free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _process_cpu(pid: int) -> float:
    """User+sys seconds of process ``pid`` so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Devices:
    """``pnp sim up`` of the cell in a process of its own, on a private SSDP port."""

    def __init__(self, folder: Path, parts: int | None) -> None:
        self.port = _free_udp_port()
        env = {**os.environ, "PNP_SSDP_PORT": str(self.port),
               "PYTHONPATH": os.pathsep.join(p for p in (str(ROOT / "src"), os.environ.get("PYTHONPATH", "")) if p)}
        args = [sys.executable, "-m", "plugnproduce", "sim", "up", str(CELL), "--state-file", str(folder / "sim")]
        if parts is not None:
            args += ["--bin-parts", str(parts)]
        self.process = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    def wait_up(self) -> None:
        """Until the cell says it is up (its line on standard output)."""
        deadline = time.monotonic() + READY_SECONDS
        assert self.process.stdout is not None
        for line in self.process.stdout:
            if " is up " in line:
                return
            if time.monotonic() > deadline:
                break
        raise SystemExit(f"pnp sim up did not come up (exit {self.process.poll()})")

    def stop(self) -> None:
        """Stop the cell's process (SIGTERM, as Ctrl-C would) and wait for it."""
        self.process.terminate()
        try:
            self.process.wait(30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


async def one_run(task: Path, journal: Path, devices_pid: int) -> tuple[float, float, float, int, float]:
    """The controller's CPU, the devices' busy time, the devices' process CPU, the steps and the wall time of one
    run."""
    marks: dict[str, float] = {}

    def started(_: object) -> None:
        marks["cpu"], marks["devices"] = time.process_time(), _process_cpu(devices_pid)
        marks["wall"] = time.perf_counter()

    report = await controller.run_task(task, CELL, journal=journal, started=started)
    cpu, devices_cpu = time.process_time() - marks["cpu"], _process_cpu(devices_pid) - marks["devices"]
    wall = time.perf_counter() - marks["wall"]
    if report.outcome != "succeeded":
        raise SystemExit(f"{task.name}: the run ended {report.outcome}: {report.fault}")
    records = read_journal(report.journal).records
    steps = sum(1 for r in records if r["kind"] == "step")
    return cpu, busy_time(records), devices_cpu, steps, wall


def measure(name: str, runs: int, parts: int, folder: Path) -> None:
    """Print the controller's CPU per step and its share of the devices' busy time for task ``name``."""
    shares, per_step, device_share, idle = [], [], [], []
    load = os.getloadavg()[0]
    for i in range(runs):
        devices = Devices(folder, parts if name == "until-empty" else None)
        try:
            devices.wait_up()
            os.environ["PNP_SSDP_PORT"] = str(devices.port)
            cpu, busy, devices_cpu, steps, wall = asyncio.run(one_run(TASKS[name], folder / f"{name}-{i}.jsonl",
                                                                devices.process.pid))
        finally:
            devices.stop()
        shares.append(cpu / busy)
        per_step.append(cpu / steps)
        device_share.append(devices_cpu / busy)
        idle.append((wall - busy) / wall)
        print(f"  run {i + 1}: {steps} steps, controller CPU {cpu:.3f} s, devices busy {busy:.2f} s, "
              f"devices' process CPU {devices_cpu:.3f} s, wall {wall:.2f} s", flush=True)
    share = statistics.median(shares)
    print(f"{name}: controller CPU {1000 * statistics.median(per_step):.2f} ms per step = {100 * share:.1f} % of "
          f"the devices' busy time (target <= {100 * TARGET:.0f} %; devices' own process "
          f"{100 * statistics.median(device_share):.1f} %); no device busy {100 * statistics.median(idle):.1f} % of "
          f"the run's wall time | load {load:.2f} -> {os.getloadavg()[0]:.2f}",
          flush=True)


def main() -> None:
    """Run the benchmark and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--parts", type=int, default=20, help="parts in the bin of the until-empty task")
    parser.add_argument("--tasks", nargs="+", choices=sorted(TASKS), default=sorted(TASKS))
    args = parser.parse_args()
    service.knowledge_for_cell(CELL)  # the knowledge loaded before any run, as a long-lived controller has it
    with tempfile.TemporaryDirectory() as folder:
        for name in args.tasks:
            measure(name, args.runs, args.parts, Path(folder))


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    main()
