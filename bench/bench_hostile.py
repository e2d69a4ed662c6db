"""Benchmark of refusing hostile input (prints figures; not a test).

    python bench/bench_hostile.py [--rounds 3]

Wall time and peak memory of ``pnp validate`` on hostile files (billion laughs, an
external entity, a YAML alias bomb, 50 MB of XML, a million nested YAML brackets),
against ``pnp validate`` of the small, valid gripper description measured in the same
run. Target on an idle machine: each refused within 2 s, under 400 MB. (The tests check
that each is refused and how much memory it takes, not how fast.)
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAUGHS = "\n".join(f' <!ENTITY lol{i} "{f"&lol{i - 1};" * 10}">' for i in range(1, 10))
BILLION_LAUGHS = (f'<?xml version="1.0"?>\n<!DOCTYPE lolz [\n <!ENTITY lol0 "lol">\n{LAUGHS}\n]>\n'
                  '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0"><state id="&lol9;"/></scxml>\n')
EXTERNAL_ENTITY = ('<?xml version="1.0"?>\n<!DOCTYPE scxml [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>\n'
                   '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0"><state id="a">&xxe;</state></scxml>\n')
YAML_BOMB = "a: &a [x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a]\nc: [*b, *b, *b, *b]\n"


def _files(folder: Path) -> dict[str, Path]:
    files = {"billion laughs": ("lol.scxml", BILLION_LAUGHS), "external entity": ("xxe.scxml", EXTERNAL_ENTITY),
             "RDF/XML bomb as Turtle": ("lol.ttl", BILLION_LAUGHS), "YAML aliases": ("bomb.yaml", YAML_BOMB),
             "1e6 nested YAML": ("deep.yaml", "[" * 1_000_000)}
    out = {}
    for name, (file, text) in files.items():
        out[name] = folder / file
        out[name].write_text(text, encoding="utf-8")
    huge = folder / "huge.scxml"
    with huge.open("wb") as f:
        f.write(b'<scxml xmlns="http://www.w3.org/2005/07/scxml"><!-- ' + b"x" * (50 * 1024 * 1024) + b" --></scxml>")
    out["50 MB"] = huge
    return out


def _validate(path: Path) -> tuple[float, float, int, float]:
    """Seconds, peak MB, exit code and CPU seconds (user+sys of the child) of ``pnp validate path``."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (str(ROOT / "src"), os.environ.get("PYTHONPATH"))))}
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "plugnproduce", "validate", str(path)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    return (time.perf_counter() - start, usage.ru_maxrss / 1024, os.waitstatus_to_exitcode(status),
            usage.ru_utime + usage.ru_stime)


def main(rounds: int) -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    baseline_file = ROOT / "descriptions" / "devices" / "gripper.ttl"
    _validate(baseline_file)  # warm: byte code and the taxonomy cache
    with tempfile.TemporaryDirectory() as folder:
        files = {"valid gripper (baseline)": baseline_file, **_files(Path(folder))}
        results = {name: [_validate(path) for _ in range(rounds)] for name, path in files.items()}
    base = statistics.median(r[0] for r in results["valid gripper (baseline)"])
    base_cpu = statistics.median(r[3] for r in results["valid gripper (baseline)"])
    print(f"pnp validate, median of {rounds} (load average now {os.getloadavg()[0]:.2f}):")
    for name, runs in results.items():
        seconds = statistics.median(r[0] for r in runs)
        peak, cpu = max(r[1] for r in runs), statistics.median(r[3] for r in runs)
        print(f"  {name:<26} {seconds:6.2f} s = {seconds / base:4.2f}× baseline, CPU {cpu:6.2f} s = "
              f"{cpu / base_cpu:4.2f}× baseline, peak {peak:5.0f} MB, exit {runs[0][2]}")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    main(parser.parse_args().rounds)
