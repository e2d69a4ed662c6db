"""The long fuzz run: the targets of ``tests/fuzz`` for as many cases as asked, in process.

    python scripts/fuzz.py --cases 100000 --seed 1

Each case is a built-in example damaged by random mutations (see ``tests/fuzz/fuzzing.py``),
read through the project's real entry point. Printed per target: cases, accepted, refused
cleanly, tracebacks (an unexpected exception type, a message of several lines or quoting
the input at length, a warning or a library's log line on the way), and budget overruns.
Crashers and overruns are written to ``--save`` to become regression cases. Exit 1 if any
case crashed or overran, else 0.

Budgets. A case overruns when it

- uses more than ``--max-seconds`` of CPU time: the process's own (every thread, so the
  HMI's server thread too) plus that of the child processes it started and waited for
  (Graphviz, a reasoner's JVM). CPU time is the work the program did for the case; it
  hardly changes when other programs share the cores, where wall-clock time doubles.
- takes longer than ``--max-wall`` seconds of wall-clock time: the ceiling that still
  catches a case that sleeps, waits on a lock or a socket, or hangs, which uses no CPU.
  It is far above the CPU budget so a busy machine alone does not reach it. A case still
  running at ``HANG_FACTOR`` (5) times that ceiling is a hang: every thread's stack is
  printed and the run ends (exit 1).
- grows the process's peak resident memory by more than ``--max-mb``.

The table gives each target's cases per CPU second, and the total line the wall-clock
time of the run and the largest CPU and wall-clock time of one case.
"""

from __future__ import annotations

import argparse
import faulthandler
import logging
import random
import resource
import sys
import time
import traceback
import warnings
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "fuzz"))

import fuzzing  # noqa: E402  (the shared targets live beside the tests)

from plugnproduce.cli.application import quiet_library_chatter  # noqa: E402

WEIGHTS = {"turtle": 14, "chart": 14, "task": 14, "cell": 8, "xirp": 30, "served": 8, "reference": 4, "hmi": 8,
           "upnp": 6, "ssdp": 6}
"""Share of the cases each target gets."""

HANG_FACTOR = 5.0
"""A case still running at this multiple of the wall-clock ceiling is a hang: stacks are printed, the run ends."""


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


def _cpu_seconds() -> float:
    """CPU time of this process (all threads) and of its children that ended and were waited for."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@dataclass(frozen=True)
class Budget:
    """What one case may use: CPU seconds, wall-clock seconds (the hang ceiling) and peak memory growth."""

    cpu: float
    wall: float
    mb: float

    def overrun(self, cpu: float, wall: float, mb: float) -> str | None:
        """Why a case that used ``cpu`` and ``wall`` seconds and grew the peak by ``mb`` overran, or None."""
        over = [f"{cpu:.1f} s CPU" if cpu > self.cpu else "", f"{wall:.1f} s wall-clock" if wall > self.wall else "",
                f"+{mb:.0f} MB" if mb > self.mb else ""]
        if not any(over):
            return None
        return f"overrun ({', '.join(o for o in over if o)}; {cpu:.1f} s CPU, {wall:.1f} s wall-clock, +{mb:.0f} MB)"


@dataclass
class Tally:
    """Counts per target, the signatures of what went wrong, and the costliest case."""

    counts: dict[str, Counter[str]]
    cpu: Counter[str] = field(default_factory=Counter)
    signatures: Counter[str] = field(default_factory=Counter)
    worst_cpu: float = 0.0
    worst_wall: float = 0.0

    def bad(self, kind: str) -> int:
        """How many cases of all targets ended as ``kind`` (``traceback`` or ``overrun``)."""
        return sum(c[kind] for c in self.counts.values())


def _save(folder: Path | None, name: str, data: bytes) -> None:
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)


def _outcome(target: str, run: Callable[[], str], chatter: _Chatter, tally: Tally) -> str:
    """Run one case; an unexpected exception, a warning or a library's log line is a traceback."""
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
            where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
            signature = f"{target}: {type(exc).__name__}: {' '.join(str(exc).split())[:160]}"  # one line each
            if where is not None and not isinstance(exc, fuzzing.Crash):
                signature += f" (at {Path(where.filename).name}:{where.lineno})"
            tally.signatures[signature] += 1
            return "traceback"
        finally:
            chatter.records.clear()
    return outcome


def _run_case(i: int, target: str, make: Callable[[int], tuple[bytes, Callable[[], str]]], chatter: _Chatter,
              budget: Budget, tally: Tally, save: Path | None) -> None:
    """Make case ``i`` of ``target``, run it within ``budget`` and count it."""
    data, run = make(i)
    faulthandler.dump_traceback_later(budget.wall * HANG_FACTOR, exit=True)
    peak, cpu0, wall0 = _peak_mb(), _cpu_seconds(), time.perf_counter()
    outcome = _outcome(target, run, chatter, tally)
    cpu, wall, mb = _cpu_seconds() - cpu0, time.perf_counter() - wall0, _peak_mb() - peak
    faulthandler.cancel_dump_traceback_later()
    if outcome == "traceback":
        _save(save, f"{target}-{i}.bin", data)
    counts = tally.counts[target]
    counts["cases"] += 1
    counts[outcome] += 1
    tally.cpu[target] += cpu
    tally.worst_cpu, tally.worst_wall = max(tally.worst_cpu, cpu), max(tally.worst_wall, wall)
    why = budget.overrun(cpu, wall, mb)
    if why is not None:
        counts["overrun"] += 1
        tally.signatures[f"{target}: {why}"] += 1
        _save(save, f"{target}-{i}-overrun.bin", data)


def _arguments() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=100_000, help="cases in total, shared by WEIGHTS")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--targets", default=",".join(WEIGHTS), help="comma-separated subset of " + ",".join(WEIGHTS))
    parser.add_argument("--deep-every", type=int, default=20,
                        help="validate every Nth description case in full as 'pnp validate' does (slow)")
    parser.add_argument("--max-seconds", type=float, default=5.0, help="CPU-time budget per case (seconds)")
    parser.add_argument("--max-wall", type=float, default=60.0,
                        help="wall-clock ceiling per case (seconds): catches sleeps, waits and hangs")
    parser.add_argument("--max-mb", type=float, default=200.0, help="peak memory growth budget per case")
    parser.add_argument("--save", type=Path, default=None, help="folder to write crashing inputs to")
    args = parser.parse_args()
    unknown = {t for t in args.targets.split(",") if t} - set(WEIGHTS)
    if unknown:
        parser.error(f"unknown targets: {', '.join(sorted(unknown))}")
    return args


def _print(tally: Tally, targets: list[str], wall: float, seed: int) -> None:
    print(f"{'target':<10}{'cases':>9}{'accepted':>10}{'refused':>9}{'tracebacks':>12}{'overruns':>10}"
          f"{'cases/CPU s':>13}")
    for t in targets:
        c = tally.counts[t]
        rate = c["cases"] / tally.cpu[t] if tally.cpu[t] else 0.0
        print(f"{t:<10}{c['cases']:>9}{c['accepted']:>10}{c['refused']:>9}{c['traceback']:>12}{c['overrun']:>10}"
              f"{rate:>13.0f}")
    n = sum(c["cases"] for c in tally.counts.values())
    print(f"total: {n} cases in {wall:.0f} s ({n / wall:.0f}/s), seed {seed}, {tally.bad('traceback')} tracebacks, "
          f"{tally.bad('overrun')} overruns, peak {_peak_mb():.0f} MB; costliest case {tally.worst_cpu:.1f} s CPU, "
          f"slowest {tally.worst_wall:.1f} s wall-clock")
    for signature, k in tally.signatures.most_common(30):
        print(f"  {k:>6}  {signature}")


def main() -> int:
    """Run the campaign and print the counts."""
    args = _arguments()
    targets = [t for t in args.targets.split(",") if t]
    budget = Budget(args.max_seconds, args.max_wall, args.max_mb)
    rng = random.Random(args.seed)
    ws = fuzzing.Workspace()
    hmi = fuzzing.InProcessHmi(ws.root / "runs") if "hmi" in targets else None
    quiet_library_chatter()  # logging configured as the command line and the HMI it serves do
    chatter = _Chatter()
    logging.getLogger().addHandler(chatter)
    makers = _cases(rng, ws, hmi, max(args.deep_every, 1))
    total = sum(WEIGHTS[t] for t in targets)
    plan = {t: args.cases * WEIGHTS[t] // total for t in targets}
    plan[targets[0]] += args.cases - sum(plan.values())
    order = [t for t, n in plan.items() for _ in range(n)]
    rng.shuffle(order)
    tally = Tally({t: Counter() for t in targets})
    started = time.perf_counter()
    try:
        for i, target in enumerate(order):
            _run_case(i, target, makers[target], chatter, budget, tally, args.save)
            if (i + 1) % 1000 == 0:
                rate = (i + 1) / (time.perf_counter() - started)
                print(f"... {i + 1} cases, {rate:.0f}/s, {tally.bad('traceback')} tracebacks, "
                      f"{tally.bad('overrun')} overruns", file=sys.stderr, flush=True)
    finally:
        logging.getLogger().removeHandler(chatter)
        if hmi is not None:
            hmi.close()
        ws.close()
    _print(tally, targets, time.perf_counter() - started, args.seed)
    return 1 if tally.bad("traceback") + tally.bad("overrun") else 0


if __name__ == "__main__":
    sys.exit(main())
