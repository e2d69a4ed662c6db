"""Benchmark of the SCXML runtime against python-statemachine (prints figures; not a test).

    python bench/bench_statechart.py [--events 20000] [--sizes 10,100,1000] [--repeat 3]

1. a synthetic chart, a toggle (two states, one event): external events per second, each
   a whole macrostep;
2. closed-world charts (the generated controller and the four device models in one
   chart) that grow with the size axis: 10, 100 and 1,000 *distinct* steps. The generator
   shares one chart among steps that take the same paths (a repeated task is one 19 KiB
   chart however long), so the bin-picking task's two generated steps (bin-pick, place) are
   unrolled here, each step a copy of its generated chart under its own state ids, with the
   plan naming each one: the chart grows linearly with the steps. Measured: events per second
   of a session of the chart already read (this runtime: a new interpreter, its compilation
   included; python-statemachine: a new machine of the class it built), and of whole runs
   from the SCXML text (reading included on both sides).

The only delayed sends are the controller's command timeouts, cancelled when the device
answers. python-statemachine keeps them on a wall-clock heap: under load a short timeout
can expire before its answer is taken, and the run ends ``failed``. So both engines get the
same delay, :data:`TIMEOUT`, far longer than any run; every run must still end in ``done``.

Each figure is printed in wall time and in CPU time of this process (user+sys), with the
ratio of each; the load average is printed at the start and the end.

Each figure is the best of ``--repeat`` measurements, with the garbage collector as the
program leaves it: the benchmark does not touch it (the runtime keeps the collector off
large charts itself, see ``plugnproduce.statechart.gcpause``). Target: at least 10x
python-statemachine on every chart.
"""

from __future__ import annotations

import argparse
import atexit
import os
import re
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

from statemachine.io.model import StateMachineDefinition
from statemachine.io.scxml.processor import SCXMLProcessor
from statemachine.io.scxml.reader import parse_scxml

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
TIMEOUT = "3600s"
"""The delay of every delayed send (the controller's command timeouts) in both engines: far longer than a run."""
STEP_ID = r"(?<![\w-])s{}(?![0-9A-Za-z-])"
"""A step's state id where the generated chart writes it (``s1``, ``s1_robot``, ``done.state.s1``, ``In('s1_x')``)."""


def best_rate(count: int, work: Callable[[], object], repeat: int) -> tuple[float, float]:
    """``count`` things done by ``work``, per second of wall time and per second of CPU time (user+sys of this
    process), each in the fastest of ``repeat`` runs."""
    wall = cpu = float("inf")
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        work()
        cpu = min(cpu, time.process_time() - start_cpu)
        wall = min(wall, time.perf_counter() - start)
    return count / wall, count / max(cpu, 1e-9)


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
    return partial(processor.start().send, "toggle")  # type: ignore[no-untyped-call]


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


def run_theirs(definition: StateMachineDefinition) -> None:
    """One session of python-statemachine on the chart already read: a machine class built from the read
    definition (as this runtime compiles its model for each new interpreter), started, run to its end.

    A class built once cannot run two sessions: it initialises the datamodel once per class (a flag in
    the ``<datamodel>`` action's closure), so a second machine starts without its data and ends
    ``failed``, under load or not. Hence one class per session.
    """
    processor = SCXMLProcessor()
    processor.process_definition(definition, location="closed_world")
    _finished(processor)


def _finished(processor: SCXMLProcessor) -> None:
    configuration = set(processor.start().configuration_values)  # type: ignore[no-untyped-call]
    if configuration != {"done"}:
        raise RuntimeError(f"python-statemachine ended in {configuration}; expected {{'done'}}")


def whole_ours(data: bytes) -> None:
    run_ours(parse_chart(data, "closed-world"))


def whole_theirs(text: str) -> None:
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", text)
    _finished(processor)


def report(what: str, ours: tuple[float, float], theirs: tuple[float, float]) -> None:
    """One row: wall-time and CPU-time rates of both engines and their ratios."""
    print(f"{what}:\n  wall {ours[0]:,.0f} events/s here, {theirs[0]:,.0f} python-statemachine: "
          f"{ours[0] / theirs[0]:.1f}x | CPU {ours[1]:,.0f} events/s here, {theirs[1]:,.0f} python-statemachine: "
          f"{ours[1] / theirs[1]:.1f}x (target >= 10x)", flush=True)


def generated_world() -> str:
    """The closed-world chart of the bin-picking task once (steps 1 and 2: bin-pick, place), every delay
    :data:`TIMEOUT`."""
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    task = service.builtin("tasks", "bin-picking.yaml").read_text(encoding="utf-8")
    if "repeat: 3" not in task:
        raise SystemExit("the bin-picking task no longer repeats 3 times: update this benchmark")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "once.yaml"
        path.write_text(task.replace("repeat: 3", "repeat: 1"), encoding="utf-8")
        text = closed_world_chart(service.generate(path, cell).task, cell).decode()
    return re.sub(r'delay="[^"]*"', f'delay="{TIMEOUT}"', text)


def _element(text: str, tag: str, ident: str) -> tuple[int, int]:
    """Where the element ``<tag id="ident"`` starts and ends in ``text``."""
    start = text.index(f'<{tag} id="{ident}"')
    depth, at = 0, start
    for match in re.finditer(rf"<{tag}[\s>]|</{tag}>", text[start:]):
        depth += -1 if match.group().startswith("</") else 1
        at = start + match.end()
        if depth == 0:
            return start, at
    raise ValueError(f"{tag} {ident} is not closed")


def closed_world(steps: int) -> bytes:
    """A closed-world chart of ``steps`` distinct steps: the generated bin-pick and place steps alternately, each
    a copy under its own ids (``s1`` … ``sN``), the plan running them in order."""
    text = generated_world()
    templates = [text[slice(*_element(text, "parallel", f"s{k}"))] for k in (1, 2)]
    body = "\n      ".join(re.sub(STEP_ID.format(1 + k % 2), f"s{k + 1}", templates[k % 2]) for k in range(steps))
    first, last = _element(text, "parallel", "s1")[0], _element(text, "parallel", "s2")[1]
    choices = "".join(f'\n        <transition cond="pnp_plan[pnp_step] == {k}" target="s{k}"/>'
                      for k in range(1, steps + 1))
    text = text[:first] + body + text[last:]
    text = re.sub(r'(<state id="next_step">)(\s*<transition cond="pnp_plan\[pnp_step\] == [12]" target="s[12]"/>)+',
                  lambda m: m.group(1) + choices, text)
    plan = ", ".join(map(str, [*range(1, steps + 1), 0]))
    return re.sub(r'<data id="pnp_plan" expr="[^"]*"/>', f'<data id="pnp_plan" expr="[{plan}]"/>', text).encode()


def main(events: int, sizes: list[int], repeat: int) -> None:
    report("toggle (synthetic)", best_rate(events, times(events, toggle_ours()), repeat),
           best_rate(events, times(events, toggle_theirs()), repeat))
    for steps in sizes:
        data = closed_world(steps)
        chart = parse_chart(data, "closed-world")
        per_run = run_ours(chart)
        runs = max(1, 100 // steps)  # python-statemachine takes minutes a run at 1,000 distinct steps
        definition = parse_scxml(data.decode())
        count = runs * per_run
        ours = best_rate(count, times(runs, partial(run_ours, chart)), repeat)
        report(f"{steps} distinct steps closed world ({len(data) // 1024} KiB, {per_run} events a run), session of "
               "the read chart", ours, best_rate(count, times(runs, partial(run_theirs, definition)), repeat))
        report(f"{steps} distinct steps closed world, whole run from the SCXML text",
               best_rate(count, times(runs, partial(whole_ours, data)), repeat),
               best_rate(count, times(runs, partial(whole_theirs, data.decode())), repeat))
        print(f"  {steps} distinct steps: {1e6 / ours[1]:.1f} µs of CPU per event here, compilation included")


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--events", type=int, default=20000, help="toggle events per measurement")
    parser.add_argument("--sizes", default="10,100,1000", help="closed-world chart sizes, in distinct task steps")
    parser.add_argument("--repeat", type=int, default=3, help="measurements; the best counts")
    args = parser.parse_args()
    main(args.events, [int(s) for s in args.sizes.split(",")], args.repeat)
