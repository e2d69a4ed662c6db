"""The long fuzz run: the targets of ``tests/fuzz`` for as many cases as asked, in process.

    python scripts/fuzz.py --cases 100000 --seed 1

Each case is a built-in example damaged by random mutations (see ``tests/fuzz/fuzzing.py``),
read through the project's real entry point. Printed per target: cases, accepted, refused
cleanly, tracebacks (an unexpected exception type, a message of several lines or quoting
the input at length, a warning or a library's log line on the way), and budget overruns (a
case slower than ``--max-seconds`` or growing the peak memory by more than ``--max-mb``).
Crashers are written to ``--save`` to become regression cases. Exit 1 if any case crashed
or overran, else 0.
"""

from __future__ import annotations

import argparse
import logging
import random
import resource
import sys
import time
import traceback
import warnings
from collections import Counter
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "fuzz"))

import fuzzing  # noqa: E402  (the shared targets live beside the tests)

WEIGHTS = {"turtle": 14, "chart": 14, "task": 14, "cell": 8, "xirp": 30, "served": 8, "reference": 4, "hmi": 8,
           "upnp": 6, "ssdp": 6}
"""Share of the cases each target gets."""


class _Chatter(logging.Handler):
    """Collects log records of other libraries than the project's (they would reach a user's terminal)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        if not record.name.startswith("plugnproduce"):
            self.records.append(record)


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _cases(rng: random.Random, ws: fuzzing.Workspace, hmi: fuzzing.InProcessHmi | None,
           deep_every: int) -> dict[str, Callable[[int], tuple[bytes, Callable[[], str]]]]:
    """Per target, a function that makes case ``i``: the input (to record) and the call that runs it."""
    kinds = {k: fuzzing.seeds(k) for k in ("turtle", "chart", "task", "cell")}
    xirp = fuzzing.xirp_seeds()
    devices = [(r.split("/")[1].removesuffix(".ttl"), d) for r, d in kinds["turtle"] if r.startswith("devices/")]
    charts = {r.split("/")[1].removesuffix(".scxml"): d for r, d in kinds["chart"] if r.startswith("devices/")}
    requests = fuzzing.hmi_requests()
    root, scpd = fuzzing.upnp_seeds()
    ssdp = fuzzing.ssdp_seeds()
    runners = {"turtle": fuzzing.run_turtle, "chart": fuzzing.run_chart, "task": fuzzing.run_task,
               "cell": fuzzing.run_cell}

    def description(kind: str) -> Callable[[int], tuple[bytes, Callable[[], str]]]:
        def case(i: int) -> tuple[bytes, Callable[[], str]]:
            relative, data = rng.choice(kinds[kind])
            data = fuzzing.mutate(data, rng)
            return relative.encode() + b"\n" + data, lambda: runners[kind](ws, relative, data, i % deep_every == 0)
        return case

    def xirp_case(i: int) -> tuple[bytes, Callable[[], str]]:
        data = fuzzing.mutate(rng.choice(xirp), rng)
        return data, lambda: fuzzing.run_xirp(data)

    def served_case(i: int) -> tuple[bytes, Callable[[], str]]:
        name, ttl = rng.choice(devices)
        chart = charts[name]
        if rng.random() < 0.5:
            ttl = fuzzing.mutate(ttl, rng)
        else:
            chart = fuzzing.mutate(chart, rng)
        return (name.encode() + b"\n" + ttl + b"\n----\n" + chart,
                lambda: fuzzing.run_served(ws, name, ttl, chart, "http://127.0.0.1:8000/dev/description.xml"))

    def reference_case(i: int) -> tuple[bytes, Callable[[], str]]:
        ref = fuzzing.mutate(rng.choice(fuzzing.REFERENCES).encode(), rng).decode("utf-8", "replace")
        return ref.encode(), lambda: fuzzing.run_reference("http://127.0.0.1:8000/dev/description.xml", ref)

    def hmi_case(i: int) -> tuple[bytes, Callable[[], str]]:
        assert hmi is not None
        request = fuzzing.mutate_request(rng.choice(requests), rng)
        return repr(request).encode(), lambda: fuzzing.run_hmi(hmi, request)

    def upnp_case(i: int) -> tuple[bytes, Callable[[], str]]:
        which = rng.choice(("root", "scpd", "both"))
        r = fuzzing.mutate(root, rng) if which != "scpd" else root
        s = fuzzing.mutate(scpd, rng) if which != "root" else scpd
        return r + b"\n----\n" + s, lambda: fuzzing.run_upnp_description(r, s)

    def ssdp_case(i: int) -> tuple[bytes, Callable[[], str]]:
        data = fuzzing.mutate(rng.choice(ssdp), rng)
        return data, lambda: fuzzing.run_ssdp(data)

    out = {k: description(k) for k in runners} | {"xirp": xirp_case, "served": served_case,
                                                  "reference": reference_case, "upnp": upnp_case, "ssdp": ssdp_case}
    if hmi is not None:
        out["hmi"] = hmi_case
    return out


def main() -> int:
    """Run the campaign and print the counts."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=100_000, help="cases in total, shared by WEIGHTS")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--targets", default=",".join(WEIGHTS), help="comma-separated subset of " + ",".join(WEIGHTS))
    parser.add_argument("--deep-every", type=int, default=20,
                        help="validate every Nth description case in full as 'pnp validate' does (slow)")
    parser.add_argument("--max-seconds", type=float, default=5.0, help="budget per case")
    parser.add_argument("--max-mb", type=float, default=200.0, help="peak memory growth budget per case")
    parser.add_argument("--save", type=Path, default=None, help="folder to write crashing inputs to")
    args = parser.parse_args()

    targets = [t for t in args.targets.split(",") if t]
    unknown = set(targets) - set(WEIGHTS)
    if unknown:
        parser.error(f"unknown targets: {', '.join(sorted(unknown))}")
    rng = random.Random(args.seed)
    ws = fuzzing.Workspace()
    hmi = fuzzing.InProcessHmi(ws.root / "runs") if "hmi" in targets else None
    chatter = _Chatter()
    logging.getLogger().addHandler(chatter)
    makers = _cases(rng, ws, hmi, max(args.deep_every, 1))
    total = sum(WEIGHTS[t] for t in targets)
    plan = {t: args.cases * WEIGHTS[t] // total for t in targets}
    plan[targets[0]] += args.cases - sum(plan.values())
    order = [t for t, n in plan.items() for _ in range(n)]
    rng.shuffle(order)

    counts: dict[str, Counter[str]] = {t: Counter() for t in targets}
    seconds: Counter[str] = Counter()
    signatures: Counter[str] = Counter()
    started = time.perf_counter()
    try:
        for i, target in enumerate(order):
            peak = _peak_mb()
            t0 = time.perf_counter()
            data, run = makers[target](i)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    outcome = run()
                    if caught:
                        raise fuzzing.Crash(f"warning: {caught[0].category.__name__}: {str(caught[0].message)[:200]}")
                    if chatter.records:
                        record = chatter.records[0]
                        raise fuzzing.Crash(f"log line from {record.name}: {record.getMessage()[:200]}")
                except Exception as exc:  # noqa: BLE001 - the point: every unexpected exception is counted
                    outcome = "traceback"
                    where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
                    signature = f"{target}: {type(exc).__name__}: {str(exc)[:160]}"
                    if where is not None and not isinstance(exc, fuzzing.Crash):
                        signature += f" (at {Path(where.filename).name}:{where.lineno})"
                    signatures[signature] += 1
                    if args.save is not None:
                        args.save.mkdir(parents=True, exist_ok=True)
                        (args.save / f"{target}-{i}.bin").write_bytes(data)
                finally:
                    chatter.records.clear()
            elapsed = time.perf_counter() - t0
            seconds[target] += elapsed
            counts[target]["cases"] += 1
            counts[target][outcome] += 1
            if elapsed > args.max_seconds or _peak_mb() - peak > args.max_mb:
                counts[target]["overrun"] += 1
                signatures[f"{target}: overrun ({elapsed:.1f} s, +{_peak_mb() - peak:.0f} MB)"] += 1
                if args.save is not None:
                    args.save.mkdir(parents=True, exist_ok=True)
                    (args.save / f"{target}-{i}-overrun.bin").write_bytes(data)
            if (i + 1) % 1000 == 0:
                rate = (i + 1) / (time.perf_counter() - started)
                print(f"... {i + 1} cases, {rate:.0f}/s", file=sys.stderr, flush=True)
    finally:
        logging.getLogger().removeHandler(chatter)
        if hmi is not None:
            hmi.close()
        ws.close()

    wall = time.perf_counter() - started
    print(f"{'target':<10}{'cases':>9}{'accepted':>10}{'refused':>9}{'tracebacks':>12}{'overruns':>10}{'cases/s':>9}")
    for t in targets:
        c = counts[t]
        rate = c["cases"] / seconds[t] if seconds[t] else 0.0
        print(f"{t:<10}{c['cases']:>9}{c['accepted']:>10}{c['refused']:>9}{c['traceback']:>12}{c['overrun']:>10}"
              f"{rate:>9.0f}")
    n = sum(c["cases"] for c in counts.values())
    bad = sum(c["traceback"] + c["overrun"] for c in counts.values())
    print(f"total: {n} cases in {wall:.0f} s ({n / wall:.0f}/s), seed {args.seed}, "
          f"{sum(c['traceback'] for c in counts.values())} tracebacks, "
          f"{sum(c['overrun'] for c in counts.values())} overruns, peak {_peak_mb():.0f} MB")
    for signature, k in signatures.most_common(30):
        print(f"  {k:>6}  {signature}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
