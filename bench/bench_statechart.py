"""Benchmark of the SCXML runtime against python-statemachine (prints figures; not a test).

    python bench/bench_statechart.py [--events 20000] [--runs 20] [--repeat 5]

1. a synthetic chart, a toggle (two states, one event): external events per second, each
   a whole macrostep;
2. the closed-world chart of the bin-picking task (the generated controller and the four
   device models in one chart): events per second of a session of the
   chart already read (this runtime: a new interpreter, its compilation included;
   python-statemachine: a new machine of the class it built), and of whole runs from the
   SCXML text (reading included on both sides). Delayed sends are taken at once (this
   runtime: a manual clock; python-statemachine does not wait either).

Each figure is the best of ``--repeat`` measurements. The garbage collector's view of the
objects made while generating the chart is frozen first, so that its collections measure
the interpreters, not the ontology and the reasoner. Target: at least 10x python-statemachine.
"""

from __future__ import annotations

import argparse
import gc
import time
from collections.abc import Callable
from functools import partial

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
        events += sum(len(step.consumed) for step in interpreter.execute())
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


def main(events: int, runs: int, repeat: int) -> None:
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    data = closed_world_chart(service.generate(service.builtin("tasks", "bin-picking.yaml"), cell).task, cell)
    gc.collect()
    gc.freeze()

    report("toggle (synthetic)", best_rate(events, times(events, toggle_ours()), repeat),
           best_rate(events, times(events, toggle_theirs()), repeat))

    chart = parse_chart(data, "closed-world")
    per_run = run_ours(chart)
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", data.decode())
    count = runs * per_run
    report(f"bin-picking closed world, session of the read chart ({per_run} events a run)",
           best_rate(count, times(runs, partial(run_ours, chart)), repeat),
           best_rate(count, times(runs, partial(run_theirs, processor)), repeat))
    report("bin-picking closed world, whole run from the SCXML text",
           best_rate(count, times(runs, partial(whole_ours, data)), repeat),
           best_rate(count, times(runs, partial(whole_theirs, data.decode())), repeat))

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--events", type=int, default=20000, help="toggle events per measurement")
    parser.add_argument("--runs", type=int, default=20, help="closed-world runs per measurement")
    parser.add_argument("--repeat", type=int, default=5, help="measurements; the best counts")
    args = parser.parse_args()
    main(args.events, args.runs, args.repeat)
