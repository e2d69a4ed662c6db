"""Benchmark of ``pnp batch``: throughput on distinct device sets, agreement and speed against a naive reference.

    python bench/bench_batch.py [--agree 5000] [--distinct 100000] [--sample 2000] [--end-to-end 10000,100000,1000000]

1. agreement: on ``--agree`` random configurations of the built-in catalogue (0-7 devices, so many
   miss two devices or more), the batch and the naive reference (``naive_batch.py``) give the same
   offered processes, plausible tasks and three cheapest purchases;
2. throughput on *distinct* device sets of a larger catalogue (each built-in device four times
   over, ids suffixed): offered commands only (target >= 20,000 sets/s), then with the three
   built-in tasks and their cheapest purchases (target >= 5,000 sets/s); each figure is a ratio
   against the naive reference timed on a sample of the same sets, whose answers are checked equal;
3. end to end: ``pnp batch`` as a process on 10^4, 10^5 and 10^6 distinct configurations of that
   catalogue, JSONL in and out, with the three tasks: time (target 10^6 < 2 min) and the peak RSS
   of its largest process, which must stay flat in the number of configurations;
4. tasks with loops, branches and links (the three shipped ones), which the batch answers with the full
   check once per way their roles are bound: on ``--flow`` random configurations around the paper's
   cell, against the plain way (``pnp check``'s check of every task in every configuration), answers
   checked equal, both on one process.
"""

from __future__ import annotations

import argparse
import json
import random
import re
import resource
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from naive_batch import Naive

from plugnproduce import service
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.reasoning import Configuration, batch, engine, report
from plugnproduce.reasoning.batches import task_names

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
            lines = sum(part.count("\n") for part in report(configs, catalogue, given, k.taxonomy, k.processes,
                                                             workers=workers))
            rates[workers] = lines / (time.perf_counter() - t)
        rows = list(batch(configs[:sample], catalogue, given, k.taxonomy, k.processes, workers=1))
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


def end_to_end(folder: Path, counts: list[int], seed: int, work: Path) -> None:
    ids = sorted(d.id for d in service.catalogue(folder))
    task_args = [a for n in TASKS for a in ("--task", str(service.builtin("tasks", f"{n}.yaml")))]
    base = None
    for count in counts:
        configs = work / f"configs-{count}.jsonl"
        with configs.open("w", encoding="utf-8") as f:
            for c in distinct(ids, count, (2, 8), seed):
                f.write(json.dumps({"config": c.name, "devices": list(c.devices)}) + "\n")
        out = work / f"out-{count}.jsonl"
        t = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", RUN, sys.executable, "-m", "plugnproduce", "batch",
                               "--catalogue", str(folder), str(configs), "-o", str(out), *task_args],
                              capture_output=True, text=True, check=True)
        seconds = time.perf_counter() - t
        rss = int(done.stdout.split()[-1]) / 1024
        base = base or rss
        with out.open(encoding="utf-8") as f:
            lines = sum(1 for _ in f)
        print(f"end to end: pnp batch on {count:,} distinct configurations ({lines:,} rows) in {seconds:.1f} s "
              f"= {count / seconds:,.0f}/s; peak RSS {rss:.0f} MB ({rss / base:.2f}x the first run)"
              + (" (target < 120 s)" if count >= 1_000_000 else ""))
        configs.unlink()
        out.unlink()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--agree", type=int, default=5000)
    parser.add_argument("--distinct", type=int, default=100_000)
    parser.add_argument("--sample", type=int, default=2000)
    parser.add_argument("--end-to-end", default="10000,100000,1000000")
    parser.add_argument("--flow", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    engine(service.catalogue(), [], service.knowledge().taxonomy, service.knowledge().processes)
    agreement(args.agree, args.seed)
    with tempfile.TemporaryDirectory(prefix="pnp-bench-batch-") as tmp:
        (Path(tmp) / "catalogue").mkdir()
        folder = copies(Path(tmp) / "catalogue")
        throughput(folder, args.distinct, args.sample, args.seed)
        counts = [int(c) for c in args.end_to_end.split(",") if c]
        end_to_end(folder, counts, args.seed, Path(tmp))
    flow(args.flow, args.seed)
    print(f"(this process's own peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB)")


if __name__ == "__main__":
    main()
