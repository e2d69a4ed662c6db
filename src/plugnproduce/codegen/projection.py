"""Per-device programs (the paper's outlook, section 8): the task projected onto one device.

The device's own chart is unrolled along the path the task takes through it: one
state per visit, each with the device state's ``<onentry>`` and the transition's own
content copied verbatim, so the program receives exactly the requests the task sends
it, in order, and sends the events the controller waits for. It could be downloaded
to the device's controller and run there instead of receiving single commands.
"""

from __future__ import annotations

import copy

from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.ontology.vocabulary import local_name
from plugnproduce.statechart.io.writer import write_chart
from plugnproduce.statechart.model import Chart, Final, State, Transition, pnp


def device_program(generated: GeneratedTask, device: DeviceDescription) -> bytes:
    """The SCXML program of ``device`` for the generated task."""
    states = {s.id: s for s in device.chart.children if isinstance(s, State | Final)}
    path = [t for _, steps in generated.device_paths(device.id) for t in steps]
    visits = [device.initial] + [t.target for t in path]
    ids = [f"p{n}_{state_id}" for n, state_id in enumerate(visits)]
    root = Chart(name=f"{device.id}-program", initial=ids[:1], extra_attrs={pnp("device"): device.id})
    for n, state_id in enumerate(visits):
        last = n == len(visits) - 1
        state: State | Final = (Final if last else State)(id=ids[n], extra_attrs={pnp("deviceState"): state_id})
        concept = device.state(state_id).concept
        if concept:
            state.extra_attrs[pnp("concept")] = local_name(concept)
        state.onentry = copy.deepcopy(states[state_id].onentry[:1])
        if isinstance(state, State):
            state.transitions.append(_step(states[state_id], path[n], ids[n + 1]))
        root.children.append(state)
    return write_chart(root)


def _step(source: State | Final, transition: ChartTransition, target: str) -> Transition:
    """The chart's transition taken at this point, copied with a new target."""
    taken = source.transitions if isinstance(source, State) else []
    original = next(t for t in taken if t.line == transition.line)
    t = copy.deepcopy(original)
    t.targets = [target]
    return t
