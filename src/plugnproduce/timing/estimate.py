"""The estimated cycle time of a generated task, step by step.

A step's time follows its Specific Process State Chart: each role's region goes from state to state,
a transition starts when its region has arrived and the state it waits for (``In(...)``) has been
entered, and takes what the bound device spends on the transitions of its own chart
(:class:`~plugnproduce.timing.requests.DeviceTimer`). Regions run in parallel, so a step takes as long
as its critical path. The task's time is the sum of its steps: a loop's body counts per iteration, times
its count when the count is known (``max`` with no ``until``/``while``); a loop ended by an outcome counts
once, and the estimate says so. Protocol latency is not counted.
"""

from __future__ import annotations

from collections.abc import Mapping

from plugnproduce.codegen.specific import Flow, RegionResult, Varying
from plugnproduce.codegen.task import GeneratedTask, StepChart, step_values
from plugnproduce.description.model import ChartTransition, DeviceDescription, Loop, ProcessDescription, RegionState
from plugnproduce.description.quantities.units import convert
from plugnproduce.ontology.iris import local_name
from plugnproduce.timing.cycle import CycleTime as CycleTime
from plugnproduce.timing.cycle import LoopTime as LoopTime
from plugnproduce.timing.cycle import StepTime as StepTime
from plugnproduce.timing.requests import DeviceTimer


def estimate_task(generated: GeneratedTask) -> CycleTime:
    """The estimated cycle time of ``generated``, from the devices' durations."""
    devices = {r.device.id: r.device for s in generated.steps for r in s.regions}
    timers = {i: DeviceTimer(d) for i, d in devices.items()}  # one per device, not per step
    notes: list[str] = []
    steps = tuple(StepTime(s.step.index, s.step.command, _step_seconds(s, timers, notes)) for s in generated.steps)
    loops = tuple(_loop_time(loop, steps) for loop in generated.task.loops if _outermost(loop, generated.task.loops))
    in_loops = {i for lp in loops for i in range(lp.entry, lp.last + 1)}
    total = sum(s.seconds for s in steps if s.step not in in_loops)
    total += sum(lp.first_iteration + lp.later_iteration * ((lp.count or 1) - 1) for lp in loops)
    if any(lp.count is None for lp in loops):
        notes.append("a loop that ends on an outcome is counted once; see its seconds per iteration")
    if generated.task.branches:
        notes.append("every branch's steps are counted")
    return CycleTime(steps, loops, total, tuple(dict.fromkeys(notes)))


def _outermost(loop: Loop, loops: tuple[Loop, ...]) -> bool:
    return not any(o is not loop and o.entry <= loop.entry and loop.last <= o.last for o in loops)


def _loop_time(loop: Loop, steps: tuple[StepTime, ...]) -> LoopTime:
    first = sum(s.seconds for s in steps if loop.entry <= s.step < loop.first)
    later = sum(s.seconds for s in steps if loop.first <= s.step <= loop.last)
    known = loop.max if loop.until is None and loop.while_outcome is None else None
    return LoopTime(loop.entry, loop.last, first, later, known)


def _step_seconds(chart: StepChart, timers: Mapping[str, DeviceTimer], notes: list[str]) -> float:
    """The critical path through the step's chart: every region from its first state to its last."""
    values = step_values(chart.step, chart.process)
    entered: dict[str, float] = {}
    todo: list[tuple[RegionResult, list[tuple[RegionState, RegionState, tuple[ChartTransition, ...]]]]] = []
    for region in chart.regions:
        role = chart.process.role(region.role)
        entered[role.region[0].id] = 0.0
        edges, legs = iter(region.path), []
        for k, n in enumerate(region.legs):
            legs.append((role.region[k], role.region[k + 1], tuple(next(edges) for _ in range(n))))
        todo.append((region, legs))
    while todo:
        progressed = False
        for region, legs in todo:
            while legs and (legs[0][1].waits_for is None or legs[0][1].waits_for in entered):
                source, target, path = legs.pop(0)
                start = max(entered[source.id], entered.get(target.waits_for or "", 0.0))
                sent = _request_values(region.device, chart.process, {p: values[p] for p in target.params
                                                                       if p in values}, notes)
                entered[target.id] = start + sum(timers[region.device.id].transition(e, sent) for e in path)
                progressed = True
        todo = [(r, legs) for r, legs in todo if legs]
        if not progressed:  # regions waiting on each other: the chart's checks report it; count what ran
            break
    return max(entered.values(), default=0.0)


def _request_values(device: DeviceDescription, process: ProcessDescription, values: Mapping[str, object],
                    notes: list[str]) -> dict[str, object]:
    """What a request carries, by quantity local name, in the device's units (values known only at run time,
    from an earlier step's output, are left out)."""
    out: dict[str, object] = {}
    for name, value in values.items():
        par = process.parameter(name)
        if isinstance(value, Flow | Varying):
            if any(d.motion_of == par.quantity for d in device.durations):
                notes.append(f"{device.id}: a pose known only at run time ({name}) is timed by the chart's delay")
            continue
        unit = next((a.unit for a in device.arguments if a.quantity == par.quantity), "")
        if isinstance(value, int | float) and not isinstance(value, bool) and par.unit and unit and par.unit != unit:
            value = convert(float(value), par.unit, unit)
        out[local_name(par.quantity)] = value
    return out
