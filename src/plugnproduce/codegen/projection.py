"""Per-device programs (the paper's outlook, section 8): the task projected onto one device.

The device's own chart is followed along the paths the task takes through it: each
distinct path (one step's worth) is written once as a segment, one state per visit,
each with the device state's ``<onentry>`` and the transition's own content copied
verbatim, and the plan in the datamodel says which segment runs at each step that uses
the device. So the program receives exactly the requests the task sends it, in order,
and sends the events the controller waits for. It could be downloaded to the device's
controller and run there instead of receiving single commands.
"""

from __future__ import annotations

import copy

from plugnproduce.chartnames import NEXT, PLAN, STEP
from plugnproduce.codegen.task import GeneratedTask, plan_data
from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.ontology.iris import concept_value
from plugnproduce.statechart.io.writer import write_chart
from plugnproduce.statechart.model import Assign, Chart, Data, Final, Send, State, Transition, pnp, walk

END = "end"


def device_program(generated: GeneratedTask, device: DeviceDescription) -> bytes:
    """The SCXML program of ``device`` for the generated task."""
    segments: dict[tuple[ChartTransition, ...], int] = {}
    plan = [segments.setdefault(path, len(segments) + 1) for _, path in generated.device_paths(device.id) if path]
    last = generated.final_states.get(device.id, device.initial)
    start = _visit(device, "p0", device.initial, entry=True)
    start.transitions.append(Transition(targets=[NEXT]))
    pick = State(id=NEXT, transitions=[Transition(cond=f"{PLAN}[{STEP}] == {k}", targets=[f"q{k}_0"])
                                       for k in segments.values()])
    pick.transitions.append(Transition(cond=f"{PLAN}[{STEP}] == 0", targets=[END]))
    end = Final(id=END, extra_attrs=_visit(device, END, last, entry=False).extra_attrs)
    root = Chart(name=f"{device.id}-program", initial=["p0"], datamodel="python",
                 data=[plan_data([*plan, 0]), Data(id=STEP, expr="0")],
                 extra_attrs={pnp("device"): device.id}, children=[start, pick])
    for path, k in segments.items():
        root.children.extend(_segment(device, k, path))
    root.children.append(end)
    return write_chart(root)


def _segment(device: DeviceDescription, k: int, path: tuple[ChartTransition, ...]) -> list[State]:
    """One step's path through the device's chart: a state per visit, the last one back to the plan."""
    visits = [path[0].source] + [t.target for t in path]
    ids = [f"q{k}_{n}" for n in range(len(visits))]
    states = [_visit(device, ids[n], state_id, entry=n > 0) for n, state_id in enumerate(visits)]
    for n, t in enumerate(path):
        states[n].transitions.append(_step(device, t, ids[n + 1]))
    states[-1].transitions.append(Transition(targets=[NEXT], actions=[Assign(location=STEP, expr=f"{STEP} + 1")]))
    return states


def _visit(device: DeviceDescription, sid: str, state_id: str, *, entry: bool) -> State:
    """A visit of a device state: its annotations, and (when ``entry``) the state's first ``<onentry>``."""
    state = State(id=sid, extra_attrs={pnp("deviceState"): state_id})
    concept = device.state(state_id).concept
    if concept:
        state.extra_attrs[pnp("concept")] = concept_value(concept)
    original = _chart_state(device, state_id)
    if entry and original is not None:
        state.onentry = copy.deepcopy(original.onentry[:1])
        for node in walk(state, into_charts=False):  # a send id is an XML ID: one per visit
            if isinstance(node, Send) and node.id:
                node.id = f"{sid}__{node.id}"
    return state


def _chart_state(device: DeviceDescription, state_id: str) -> State | Final | None:
    """The chart's state ``state_id``, at any depth."""
    found = device.chart.find(state_id)
    return found if isinstance(found, State | Final) else None


def _step(device: DeviceDescription, transition: ChartTransition, target: str) -> Transition:
    """The chart's transition taken at this point, copied with a new target."""
    source = _chart_state(device, transition.origin or transition.source)  # a compound state's transition
    taken = source.transitions if isinstance(source, State) else []
    original = next(t for t in taken if t.line == transition.line)
    t = copy.deepcopy(original)
    t.targets = [target]
    return t
