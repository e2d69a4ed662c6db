"""Benchmark of ``pnp batch``: throughput on distinct device sets, agreement and speed against a naive reference.

    python bench/bench_batch.py [--agree 5000] [--distinct 100000] [--sample 2000] [--end-to-end 1000,10000,100000]
                                [--only end-to-end]

1. agreement: on ``--agree`` random configurations of the built-in catalogue (0-7 devices, so many
   miss two devices or more), the batch and the naive reference (``naive_batch.py``) give the same
   offered processes, plausible tasks and three cheapest purchases;
2. throughput on *distinct* device sets of a larger catalogue (each built-in device four times
   over, ids suffixed): offered commands only (target >= 20,000 sets/s), then with the three
   built-in tasks and their cheapest purchases (target >= 5,000 sets/s); each figure is a ratio
   against the naive reference timed on a sample of the same sets, whose answers are checked equal;
3. end to end: ``pnp batch`` as a process against the brute-force script (``naive_batch.py``, a
   straightforward per-configuration script) as a process, on the same 10^3, 10^4 and 10^5 distinct
   configurations of that catalogue (10^6 too with ``--end-to-end 1000000 --rounds 1``: minutes), JSONL in
   and out, with the three tasks: CPU time (user+sys of each process and the workers it started) and wall
   time, their ratios, the load, and the answers (offered, plausible) checked equal on every line; the batch
   also computes purchases;
4. tasks with loops, branches and links (the three shipped ones), which the batch answers with the full
   check once per way their roles are bound: on ``--flow`` random configurations around the paper's
   cell, against the plain way (``pnp check``'s check of every task in every configuration), answers
   checked equal, both on one process.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from naive_batch import Naive

from plugnproduce import service
from plugnproduce.batch import Configuration, batch, engine, report
from plugnproduce.batch.batches import task_names
from plugnproduce.description.model import Cell, DeviceDescription, Task

TASKS = ("bin-picking", "pick-and-place", "bin-picking-invalid")
COPIES = 4


def tasks(names: tuple[str, ...] = TASKS) -> list[Task]:
    return [service.task(service.builtin("tasks", f"{n}.yaml")) for n in names]


def naive(catalogue: list[DeviceDescription], given: list[Task]) -> Naive:
    k = service.knowledge()
    return Naive(catalogue, task_names(given), k.taxonomy, k.processes)


def distinct(ids: list[str], count: int, sizes: tuple[int, int], seed: int) -> list[Configuration]:
    """``count`` configurations with pairwise different device sets."""
    rng, seen, out = random.Random(seed), set(), []
    while len(out) < count:
        devices = tuple(sorted(rng.sample(ids, rng.randint(*sizes))))
        if devices not in seen:
            seen.add(devices)
            out.append(Configuration(f"c{len(out) + 1}", devices))
    return out


# ------------------------------------------------------------------ 1. agreement


_REF: Naive | None = None


def _ref_rows(part: list[Configuration]) -> list[tuple[list[str], list[str], list[tuple[tuple[str, ...], int]]]]:
    assert _REF is not None
    return [(_REF.offered(set(c.devices)), _REF.plausible(set(c.devices)), _REF.purchases(set(c.devices), 3))
            for c in part]


def _start(ref: Naive) -> None:
    global _REF
    _REF = ref


def agreement(count: int, seed: int) -> None:
    catalogue = service.catalogue()
    given = tasks(("bin-picking", "pick-and-place"))
    configs = list(service.generate_configurations(count, (0, 7), seed))
    t = time.perf_counter()
    rows = list(service.batch(configs, catalogue, list(given), workers=2, top=3))
    ours = time.perf_counter() - t
    ref = naive(catalogue, given)
    parts = [configs[i:i + 200] for i in range(0, len(configs), 200)]
    t = time.perf_counter()
    with ProcessPoolExecutor(2, initializer=_start, initargs=(ref,)) as pool:
        expected = [r for part in pool.map(_ref_rows, parts) for r in part]
    theirs = time.perf_counter() - t
    wrong = sum((list(r.offered), list(r.plausible), list(r.purchase.options) if r.purchase else []) != e
                for r, e in zip(rows, expected, strict=True))
    two = sum(bool(r.purchase and r.purchase.options and len(r.purchase.options[0][0]) >= 2) for r in rows)
    print(f"agreement: {count} configurations (2 tasks, top-3 purchases), {wrong} disagreements with the naive "
          f"reference; {two} need two devices or more; batch {ours:.2f} s, reference {theirs:.1f} s "
          f"(both on 2 processes): {theirs / ours:.0f}x")
    if wrong:
        raise SystemExit("the batch disagrees with the naive reference")


# ------------------------------------------------------------------ 2. throughput on distinct sets


def copies(folder: Path) -> Path:
    """A catalogue folder holding each built-in device COPIES times (ids suffixed -1 .. -COPIES)."""
    source = service.builtin("devices")
    for ttl in sorted(source.glob("*.ttl")):
        text = ttl.read_text(encoding="utf-8")
        name = ttl.stem
        (folder / f"{name}.scxml").write_text((source / f"{name}.scxml").read_text(encoding="utf-8"),
                                              encoding="utf-8")
        for n in range(1, COPIES + 1):
            (folder / f"{name}-{n}.ttl").write_text(re.sub(rf"\bdev:{re.escape(name)}\b", f"dev:{name}-{n}", text),
                                                    encoding="utf-8")
    return folder


def throughput(folder: Path, count: int, sample: int, seed: int) -> None:
    catalogue = service.catalogue(folder)
    configs = distinct(sorted(d.id for d in catalogue), count, (2, 8), seed)
    k = service.knowledge()
    for label, given, target in (("offered commands", [], 20_000), ("+ 3 tasks and purchases", tasks(), 5_000)):
        rates = {}
        for workers in (1, 2):
            t = time.perf_counter()
            lines = sum(part.count("\n") for part in report(configs, catalogue, given, k,
                                                             workers=workers))
            rates[workers] = lines / (time.perf_counter() - t)
        rows = list(batch(configs[:sample], catalogue, given, k, workers=1))
        ref = naive(catalogue, given)
        t = time.perf_counter()
        expected = []
        for c in configs[:sample]:
            members = set(c.devices)
            offered, plausible = ref.offered(members), ref.plausible(members)
            json.dumps({"config": c.name, "devices": list(c.devices), "offered": offered, "plausible": plausible})
            expected.append((offered, plausible))
        ref_rate = sample / (time.perf_counter() - t)
        wrong = sum((list(r.offered), list(r.plausible)) != e for r, e in zip(rows, expected, strict=True))
        print(f"throughput, {label}: {count:,} distinct sets of {len(catalogue)} devices, JSONL out: "
              f"{rates[2]:,.0f} sets/s on 2 processes ({rates[1]:,.0f}/s on 1), target >= {target:,}/s; "
              f"naive reference (offered + plausible, no purchases) {ref_rate:,.0f} sets/s on 1 process "
              f"({sample} sets, {wrong} disagreements): {rates[2] / ref_rate:.1f}x ({rates[1] / ref_rate:.1f}x "
              f"process for process)")
        if wrong:
            raise SystemExit("the batch disagrees with the naive reference")


# ------------------------------------------------------------------ 4. tasks with loops, branches, links


FLOW_TASKS = ("bin-picking-until-empty", "bin-picking-then-home", "bin-picking-in-rounds")
PAPER = ("binpicking-pc", "gripper", "robot", "sensor3d")


def flow(count: int, seed: int) -> None:
    k = service.knowledge()
    rng = random.Random(seed)
    others = sorted(d.id for d in k.devices if d.id not in PAPER)
    configs = [Configuration(f"f{n}", tuple(rng.sample(PAPER, rng.randint(2, 4))
                                            + rng.sample(others, rng.randint(0, 4)))) for n in range(count)]
    given = tasks(FLOW_TASKS)
    t = time.perf_counter()
    rows = list(service.batch(configs, list(k.devices), given, workers=1, knowledge=k))
    ours = time.perf_counter() - t
    by_id = {d.id: d for d in k.devices}
    t = time.perf_counter()
    expected = [tuple(task.name for task in given
                      if service.check(task, Cell(c.name, tuple(by_id[d] for d in c.devices)), k).plausible)
                for c in configs]
    theirs = time.perf_counter() - t
    wrong = sum(r.plausible != e for r, e in zip(rows, expected, strict=True))
    print(f"tasks with loops, branches and links: {count} configurations around the paper's cell, "
          f"{sum(bool(e) for e in expected)} with a plausible task, {wrong} disagreements; batch {ours:.1f} s "
          f"(with purchases), a check per task and configuration {theirs:.1f} s: {theirs / ours:.1f}x")
    if wrong:
        raise SystemExit("the batch disagrees with the check")


# ------------------------------------------------------------------ 3. end to end, memory


RUN = ("import resource, subprocess, sys; code = subprocess.run(sys.argv[1:]).returncode; "
       "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss); sys.exit(code)")
NAIVE = Path(__file__).resolve().parent / "naive_batch.py"


def _process(args: list[str]) -> tuple[float, float, float]:
    """Wall and CPU seconds (user+sys, with every process it started) and peak RSS (MB) of a command."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu, t = usage.ru_utime + usage.ru_stime, time.perf_counter()
    done = subprocess.run([sys.executable, "-c", RUN, *args], capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, usage.ru_utime + usage.ru_stime - cpu, int(done.stdout.split()[-1]) / 1024


def _ensure_kept(folder: Path, work: Path) -> None:
    """One batch over the catalogue and tasks, so the reasoned catalogue is in the cache folder."""
    configs = work / "one.jsonl"
    configs.write_text(json.dumps({"config": "one", "devices": []}) + "\n", encoding="utf-8")
    task_args = [a for n in TASKS for a in ("--task", str(service.builtin("tasks", f"{n}.yaml")))]
    _process([sys.executable, "-m", "plugnproduce", "batch", "--catalogue", str(folder), str(configs),
              "-o", str(work / "one-out.jsonl"), *task_args])


def _answers(path: Path) -> list[tuple[str, list[str], list[str]]]:
    with path.open(encoding="utf-8") as f:
        return [(d["config"], d["offered"], d["plausible"]) for d in map(json.loads, f)]


def end_to_end(folder: Path, counts: list[int], seed: int, work: Path, rounds: int = 3) -> None:
    """``pnp batch`` as a process against the brute-force script as a process, on the same file; the batch's
    first run (not counted) reasons over the catalogue and keeps the result, as any first batch over new files
    does, so the rounds measure a batch over files it has seen."""
    _ensure_kept(folder, work)
    ids = sorted(d.id for d in service.catalogue(folder))
    task_args = [a for n in TASKS for a in ("--task", str(service.builtin("tasks", f"{n}.yaml")))]
    for count in counts:
        configs = work / f"configs-{count}.jsonl"
        with configs.open("w", encoding="utf-8") as f:
            for c in distinct(ids, count, (2, 8), seed):
                f.write(json.dumps({"config": c.name, "devices": list(c.devices)}) + "\n")
        ours, theirs = work / f"out-{count}.jsonl", work / f"naive-{count}.jsonl"
        load = [os.getloadavg()[0]]
        runs: dict[str, list[tuple[float, float, float]]] = {"script": [], "batch": []}
        for _ in range(rounds):  # interleaved, so a burst of load hits both alike; the medians are compared
            runs["script"].append(_process([sys.executable, str(NAIVE), str(configs), "--catalogue", str(folder),
                                            *task_args, "-o", str(theirs)]))
            runs["batch"].append(_process([sys.executable, "-m", "plugnproduce", "batch", "--catalogue",
                                           str(folder), str(configs), "-o", str(ours), *task_args]))
            load.append(os.getloadavg()[0])
        script = tuple(statistics.median(r[i] for r in runs["script"]) for i in range(3))
        batch_ = tuple(statistics.median(r[i] for r in runs["batch"]) for i in range(3))
        wrong = sum(a != b for a, b in zip(_answers(ours), _answers(theirs), strict=True))
        print(f"end to end, {count:,} distinct configurations (3 tasks; median of {rounds}; load "
              f"{min(load):.1f}-{max(load):.1f} on {os.cpu_count()} cores): "
              f"pnp batch {batch_[1]:.2f} s CPU, {batch_[0]:.2f} s wall, peak RSS {batch_[2]:.0f} MB "
              f"(with purchases); brute-force script {script[1]:.2f} s CPU, {script[0]:.2f} s wall "
              f"(offered + plausible); script/batch: CPU {script[1] / batch_[1]:.2f}x, wall "
              f"{script[0] / batch_[0]:.2f}x; {wrong} disagreements")
        if wrong:
            raise SystemExit("the batch disagrees with the brute-force script")
        for p in (configs, ours, theirs):
            p.unlink()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--agree", type=int, default=5000)
    parser.add_argument("--distinct", type=int, default=100_000)
    parser.add_argument("--sample", type=int, default=2000)
    parser.add_argument("--end-to-end", default="1000,10000,100000")
    parser.add_argument("--flow", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--rounds", type=int, default=3, help="end-to-end runs of each, interleaved")
    parser.add_argument("--only", choices=["agreement", "throughput", "end-to-end", "flow"])
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    engine(service.catalogue(), [], service.knowledge())
    if args.only in (None, "agreement"):
        agreement(args.agree, args.seed)
    with tempfile.TemporaryDirectory(prefix="pnp-bench-batch-") as tmp:
        (Path(tmp) / "catalogue").mkdir()
        folder = copies(Path(tmp) / "catalogue")
        if args.only in (None, "throughput"):
            throughput(folder, args.distinct, args.sample, args.seed)
        if args.only in (None, "end-to-end"):
            end_to_end(folder, [int(c) for c in args.end_to_end.split(",") if c], args.seed, Path(tmp), args.rounds)
    if args.only in (None, "flow"):
        flow(args.flow, args.seed)
    print(f"(this process's own peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB; "
          f"load average now {os.getloadavg()[0]:.2f})")

if __name__ == "__main__":
    main()
