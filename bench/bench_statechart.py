"""Benchmark of the SCXML runtime against python-statemachine (prints figures; not a test).

    python bench/bench_statechart.py [--events 20000] [--runs 20]

1. a toggle (two states, one event): external events per second, each a whole macrostep;
2. the closed-world chart of the bin-picking task (the generated controller and the four
   device models in one chart): whole runs per second (reading the chart included) and events per
   second, delayed sends
   taken at once (this runtime: a manual clock; python-statemachine does not wait either).
Target: at least 10x python-statemachine.
"""

from __future__ import annotations

import argparse
import time

from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.clock import ManualClock
from plugnproduce.statechart.interpreter import Interpreter

TOGGLE = b"""<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="off" datamodel="python">
  <state id="off"><transition event="toggle" target="on"/></state>
  <state id="on"><transition event="toggle" target="off"/></state>
</scxml>"""


def toggle_ours(n: int) -> float:
    interpreter = Interpreter(parse_chart(TOGGLE, "toggle"))
    interpreter.start()
    t = time.perf_counter()
    for _ in range(n):
        interpreter.queue("toggle")
        interpreter.execute_once()
    return n / (time.perf_counter() - t)


def toggle_theirs(n: int) -> float:
    processor = SCXMLProcessor()
    processor.parse_scxml("toggle", TOGGLE.decode())
    machine = processor.start()
    t = time.perf_counter()
    for _ in range(n):
        machine.send("toggle")
    return n / (time.perf_counter() - t)


def closed_world_ours(chart: bytes, runs: int) -> tuple[float, int]:
    events = 0
    t = time.perf_counter()
    for _ in range(runs):
        clock = ManualClock()
        interpreter = Interpreter(parse_chart(chart, "closed-world"), clock=clock)
        events += len(interpreter.start().consumed)
        while interpreter.running:
            events += sum(len(step.consumed) for step in interpreter.execute())
            due = interpreter.next_due()
            if due is None:
                break
            clock.advance_to(due)
        assert interpreter.final_state == "done"
    return runs / (time.perf_counter() - t), events // runs


def closed_world_theirs(chart: bytes, runs: int) -> float:
    t = time.perf_counter()
    for _ in range(runs):
        processor = SCXMLProcessor()
        processor.parse_scxml("closed_world", chart.decode())
        assert set(processor.start().configuration_values) == {"done"}
    return runs / (time.perf_counter() - t)


def main(events: int, runs: int) -> None:
    ours, theirs = toggle_ours(events), toggle_theirs(events)
    print(f"toggle: {ours:,.0f} events/s here, {theirs:,.0f} events/s python-statemachine: {ours / theirs:.1f}x "
          "(target >= 10x)")
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    generated = service.generate(service.builtin("tasks", "bin-picking.yaml"), cell).task
    chart = closed_world_chart(generated, cell)
    ours_runs, per_run = closed_world_ours(chart, runs)
    theirs_runs = closed_world_theirs(chart, runs)
    print(f"bin-picking closed-world chart ({per_run} events a run): {ours_runs:,.1f} runs/s = "
          f"{ours_runs * per_run:,.0f} events/s here, {theirs_runs:,.1f} runs/s python-statemachine "
          f"(parsing included on both sides): {ours_runs / theirs_runs:.1f}x (target >= 10x)")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--events", type=int, default=20000)
    parser.add_argument("--runs", type=int, default=20)
    args = parser.parse_args()
    main(args.events, args.runs)
