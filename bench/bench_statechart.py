"""Benchmark of the SCXML runtime against python-statemachine (prints figures; not a test).

    python bench/bench_statechart.py [--events 20000] [--sizes 10,100,1000] [--repeat 3]

1. a synthetic chart, a toggle (two states, one event): external events per second, each
   a whole macrostep;
2. closed-world charts (the generated controller and the four device models in one
   chart) of long tasks, the bin-picking task's two steps repeated to 10, 100 and 1,000
   steps: events per second of a session of the chart already read (this runtime: a new
   interpreter, its compilation included; python-statemachine: a new machine of the class
   it built), and of whole runs from the SCXML text (reading included on both sides).
   Delayed sends are taken at once (this runtime: a manual clock; python-statemachine
   does not wait either). The cost per event should not grow with the chart.

Each figure is the best of ``--repeat`` measurements, with the garbage collector as the
program leaves it: the benchmark does not touch it (the runtime keeps the collector off
large charts itself, see ``plugnproduce.statechart.runtime.gcpause``). Target: at least 10x
python-statemachine on every chart.
"""

from __future__ import annotations

import argparse
import atexit
import os
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.model import Chart
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.interpreter import Interpreter

TOGGLE = b"""<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="off" datamodel="python">
  <state id="off"><transition event="toggle" target="on"/></state>
  <state id="on"><transition event="toggle" target="off"/></state>
</scxml>"""


def best_rate(count: int, work: Callable[[], object], repeat: int) -> float:
    """``count`` things done by ``work``, per second, in the fastest of ``repeat`` runs."""
    fastest = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        work()
        fastest = min(fastest, time.perf_counter() - start)
    return count / fastest


def times(n: int, work: Callable[[], object]) -> Callable[[], None]:
    """``work`` done ``n`` times."""
    def repeated() -> None:
        for _ in range(n):
            work()
    return repeated


def toggle_ours() -> Callable[[], object]:
    """One toggle event, a whole macrostep, in this runtime."""
    interpreter = Interpreter(parse_chart(TOGGLE, "toggle"))
    interpreter.start()
    return lambda: interpreter.queue("toggle").execute_once()


def toggle_theirs() -> Callable[[], object]:
    """One toggle event in python-statemachine."""
    processor = SCXMLProcessor()
    processor.parse_scxml("toggle", TOGGLE.decode())
    return partial(processor.start().send, "toggle")


def run_ours(chart: Chart) -> int:
    """One session of the closed-world chart to its end; the number of events it consumed."""
    clock = ManualClock()
    interpreter = Interpreter(chart, clock=clock)
    events = len(interpreter.start().consumed)
    while interpreter.running:
        while steps := interpreter.execute():  # a long chart has more than one call's worth of steps
            events += sum(len(step.consumed) for step in steps)
        due = interpreter.next_due()
        if due is None:
            break
        clock.advance_to(due)
    if interpreter.final_state != "done":
        raise RuntimeError(f"the closed-world chart ended in {interpreter.final_state!r}; expected 'done'")
    return events


def run_theirs(processor: SCXMLProcessor) -> None:
    configuration = set(processor.start().configuration_values)
    if configuration != {"done"}:
        raise RuntimeError(f"python-statemachine ended in {configuration}; expected {{'done'}}")


def whole_ours(data: bytes) -> None:
    run_ours(parse_chart(data, "closed-world"))


def whole_theirs(text: str) -> None:
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", text)
    run_theirs(processor)


def report(what: str, ours: float, theirs: float) -> None:
    print(f"{what}: {ours:,.0f} events/s here, {theirs:,.0f} events/s python-statemachine: "
          f"{ours / theirs:.1f}x (target >= 10x)")


def closed_world(steps: int) -> bytes:
    """The closed-world chart of the bin-picking task repeated to ``steps`` steps."""
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    task = service.builtin("tasks", "bin-picking.yaml").read_text(encoding="utf-8")
    per_round = task.count("- command:")
    if "repeat: 3" not in task or steps % per_round:
        raise SystemExit(f"--sizes: multiples of the bin-picking task's {per_round} steps; found {steps}")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "long.yaml"
        path.write_text(task.replace("repeat: 3", f"repeat: {steps // per_round}"), encoding="utf-8")
        return closed_world_chart(service.generate(path, cell).task, cell)


def main(events: int, sizes: list[int], repeat: int) -> None:
    report("toggle (synthetic)", best_rate(events, times(events, toggle_ours()), repeat),
           best_rate(events, times(events, toggle_theirs()), repeat))
    for steps in sizes:
        data = closed_world(steps)
        chart = parse_chart(data, "closed-world")
        per_run = run_ours(chart)
        runs = max(1, 1000 // steps)
        processor = SCXMLProcessor()
        processor.parse_scxml("closed_world", data.decode())
        count = runs * per_run
        ours = best_rate(count, times(runs, partial(run_ours, chart)), repeat)
        report(f"{steps}-step closed world ({len(data) // 1024} KiB, {per_run} events a run), session of the "
               "read chart", ours, best_rate(count, times(runs, partial(run_theirs, processor)), repeat))
        report(f"{steps}-step closed world, whole run from the SCXML text",
               best_rate(count, times(runs, partial(whole_ours, data)), repeat),
               best_rate(count, times(runs, partial(whole_theirs, data.decode())), repeat))
        print(f"  {steps}-step: {1e6 / ours:.1f} µs per event here, compilation included")


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--events", type=int, default=20000, help="toggle events per measurement")
    parser.add_argument("--sizes", default="10,100,1000", help="closed-world chart sizes, in task steps")
    parser.add_argument("--repeat", type=int, default=3, help="measurements; the best counts")
    args = parser.parse_args()
    main(args.events, [int(s) for s in args.sizes.split(",")], args.repeat)
