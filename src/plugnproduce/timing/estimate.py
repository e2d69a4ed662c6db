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

from collections.abc import Hashable, Mapping

from plugnproduce.codegen.specific import Flow, RegionResult, Varying
from plugnproduce.codegen.task import GeneratedTask, StepChart, step_values
from plugnproduce.description.model import ChartTransition, DeviceDescription, Loop, ProcessDescription, RegionState
from plugnproduce.description.quantities.units import convert
from plugnproduce.ontology.iris import local_name
from plugnproduce.timing.cycle import CycleTime as CycleTime
from plugnproduce.timing.cycle import LoopTime as LoopTime
from plugnproduce.timing.cycle import StepTime as StepTime
from plugnproduce.timing.requests import DeviceTimer

_TimerState = tuple[float | None, object]


class StepMemo:
    """Step times already estimated, for the estimates of tasks that share most of their steps (the repairs of
    one task): a step is estimated again only when its chart, its values or the state its devices' timers
    start it from (the declared time pending, the pose a motion starts at) differ from every step seen.
    A step's time is a function of exactly these, so a task's estimate with a memo equals the one without."""

    def __init__(self) -> None:
        self._seen: dict[Hashable, tuple[float, tuple[str, ...], tuple[tuple[str, _TimerState], ...]]] = {}
        self._shapes: dict[Hashable, int] = {}
        self._devices: dict[int, tuple[str, ...]] = {}  # a shape's devices, in the order of its regions
        self._kept: dict[int, object] = {}  # what a key names by identity stays alive, so no id is reused

    def shape(self, chart: StepChart) -> int:
        """A number for what a step's time depends on besides its values and its timers: its process and its
        regions' paths through their devices' charts."""
        shape = (chart.process.id, tuple((r.role, r.device.id, id(r.device), tuple(r.legs), tuple(r.path))
                                         for r in chart.regions))
        self._kept.update((id(r.device), r.device) for r in chart.regions)
        return self._shapes.setdefault(shape, len(self._shapes))

    def seconds(self, chart: StepChart, timers: Mapping[str, DeviceTimer], notes: list[str],
                shape: int) -> float:
        """The step's seconds, leaving its devices' timers and ``notes`` as estimating it would."""
        devices = self._devices.get(shape)
        if devices is None:
            devices = self._devices[shape] = tuple(dict.fromkeys(r.device.id for r in chart.regions))
        # the step's values are its process's defaults (the shape names the process) updated with its own
        key = (shape, repr(sorted(chart.step.params.items())), tuple((d, repr(timers[d].state())) for d in devices))
        if (seen := self._seen.get(key)) is None:
            said: list[str] = []
            seconds = _step_seconds(chart, timers, said)
            seen = self._seen[key] = (seconds, tuple(said), tuple((d, timers[d].state()) for d in devices))
        seconds, said_before, after = seen
        notes.extend(said_before)
        for device, state in after:
            timers[device].resume(state)
        return seconds


def estimate_task(generated: GeneratedTask, memo: StepMemo | None = None) -> CycleTime:
    """The estimated cycle time of ``generated``, from the devices' durations (``memo``: steps estimated for
    other tasks in the same cell, which this estimate reuses and adds to)."""
    devices = {r.device.id: r.device for s in generated.steps for r in s.regions}
    timers = {i: DeviceTimer(d) for i, d in devices.items()}  # one per device, not per step
    notes: list[str] = []
    shapes: dict[int, int] = {}  # a step chart's element → its shape in the memo
    steps = tuple(StepTime(s.step.index, s.step.command, _seconds(s, timers, notes, memo, shapes))
                  for s in generated.steps)
    loops = tuple(_loop_time(loop, steps) for loop in generated.task.loops if _outermost(loop, generated.task.loops))
    in_loops = {i for lp in loops for i in range(lp.entry, lp.last + 1)}
    total = sum(s.seconds for s in steps if s.step not in in_loops)
    total += sum(lp.first_iteration + lp.later_iteration * ((lp.count or 1) - 1) for lp in loops)
    if any(lp.count is None for lp in loops):
        notes.append("a loop that ends on an outcome is counted once; see its seconds per iteration")
    if generated.task.branches:
        notes.append("every branch's steps are counted")
    return CycleTime(steps, loops, total, tuple(dict.fromkeys(notes)))


def _seconds(chart: StepChart, timers: Mapping[str, DeviceTimer], notes: list[str], memo: StepMemo | None,
             shapes: dict[int, int]) -> float:
    """The step's seconds: estimated, or as the memo has it."""
    if memo is None:
        return _step_seconds(chart, timers, notes)
    shape = shapes.get(id(chart.element))  # steps sharing a chart share its element (alive while estimating)
    if shape is None:
        shape = shapes[id(chart.element)] = memo.shape(chart)
    return memo.seconds(chart, timers, notes, shape)


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
