"""Benchmark: how fast the HMI answers cheap requests while another client's long request is worked on.

    python bench/bench_hmi_load.py [--rounds 15]

Starts ``pnp serve --sim`` (the built-in bin-picking cell) as a user would, then measures the
latency of four small requests — ``GET /api/cell``, ``GET /api/commands``, and ``POST
/api/task/check`` and ``/api/task/validate`` of a two-step task — first on the idle server
(the baseline), then while
another client keeps a validation of the largest task the editor accepts (1,000 steps) in
flight. Prints the median of each and the ratio loaded / idle, and how long the long request
took. Not a test: figures only.
"""

from __future__ import annotations

import argparse
import atexit
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]
SMALL = {"name": "small", "steps": [{"command": "bin-pick", "params": {"grip_force": 45, "exposure": 25}},
                                    {"command": "place"}]}
STEP = {"command": "place", "params": {"place_pose": [0.6, -0.2, 0.1, 0, 180, 0], "speed": 9999}}
LONG = {"name": "long", "steps": [STEP] * 1000}
CHEAP: dict[str, tuple[str, str, object]] = {
    "GET /api/cell": ("GET", "/api/cell", None),
    "GET /api/commands": ("GET", "/api/commands", None),
    "POST /api/task/check (2 steps)": ("POST", "/api/task/check", SMALL),
    "POST /api/task/validate (2 steps)": ("POST", "/api/task/validate", SMALL),
}


def _server() -> tuple[subprocess.Popen[str], str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "src"), env.get("PYTHONPATH", "")) if p)
    proc = subprocess.Popen([sys.executable, "-m", "plugnproduce", "serve", "--sim", "--port", "0"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert proc.stdout is not None
    line = proc.stdout.readline()  # "Plug'n'Produce HMI on URL"
    return proc, line.split()[-1].rstrip("/")


def _server_cpu(pid: int) -> float:
    """User+sys seconds of the server process so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _latencies(client: httpx.Client, rounds: int) -> dict[str, list[float]]:
    out: dict[str, list[float]] = {name: [] for name in CHEAP}
    for _ in range(rounds):
        for name, (method, path, body) in CHEAP.items():
            start = time.perf_counter()
            res = client.request(method, path, json=body)
            out[name].append(time.perf_counter() - start)
            res.raise_for_status()
    return out


class LongLoad:
    """Another client that keeps one long validation in flight until stopped."""

    def __init__(self, url: str) -> None:
        self.client = httpx.Client(base_url=url, timeout=600)
        self.durations: list[float] = []
        self.statuses: list[int] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.is_set():
            start = time.perf_counter()
            try:
                res = self.client.post("/api/task/validate", json=LONG)
            except httpx.HTTPError:
                return  # closed by stop()
            self.durations.append(time.perf_counter() - start)
            self.statuses.append(res.status_code)

    def __enter__(self) -> LongLoad:
        self._thread.start()
        return self

    def __exit__(self, *_: object) -> None:
        self._stop.set()
        self.client.close()  # the server stops the validation in flight
        self._thread.join(60)


def main(rounds: int) -> None:
    proc, url = _server()
    try:
        with httpx.Client(base_url=url, timeout=600) as client:
            _latencies(client, 2)  # warm: the workers' first jobs
            before = _server_cpu(proc.pid)
            idle = _latencies(client, rounds)
            idle_cpu = _server_cpu(proc.pid) - before
            with LongLoad(url) as load:
                time.sleep(1.0)  # let the long request reach its worker (a benchmark, not a test)
                before = _server_cpu(proc.pid)
                loaded = _latencies(client, rounds)
                loaded_cpu = _server_cpu(proc.pid) - before
        print(f"pnp serve --sim, bin-picking cell; {rounds} rounds of each small request; "
              "load: another client validating a 1,000-step task, one request after another")
        print(f"{'request':37} {'idle ms':>9} {'loaded ms':>10} {'ratio':>7}")
        for name in CHEAP:
            a, b = statistics.median(idle[name]) * 1000, statistics.median(loaded[name]) * 1000
            print(f"{name:37} {a:9.1f} {b:10.1f} {b / a:7.2f}")
        count = rounds * len(CHEAP)
        print(f"server process CPU (not its workers) per small request: idle {1000 * idle_cpu / count:.1f} ms, "
              f"loaded {1000 * loaded_cpu / count:.1f} ms")
        done = ", ".join(f"{d:.1f} s ({s})" for d, s in zip(load.durations, load.statuses, strict=True))
        print(f"long validations completed meanwhile: {done or 'none (still in flight, stopped at the end)'}")
    finally:
        proc.terminate()
        proc.wait(60)


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=7)
    main(parser.parse_args().rounds)
