"""Per-device programs (the paper's outlook, section 8): the task projected onto one device.

The device's own chart is unrolled along the path the task takes through it: one
state per visit, each with the device state's ``<onentry>`` and the transition's own
content copied verbatim, so the program receives exactly the requests the task sends
it, in order, and sends the events the controller waits for. It could be downloaded
to the device's controller and run there instead of receiving single commands.
"""

from __future__ import annotations

import copy

from lxml import etree

from plugnproduce.codegen.emit import SCXML_NS, el, pnp_attr, to_bytes
from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.ontology.vocabulary import concept_value
from plugnproduce.safeio import parse_xml

S = f"{{{SCXML_NS}}}"


def device_program(generated: GeneratedTask, device: DeviceDescription) -> bytes:
    """The SCXML program of ``device`` for the generated task."""
    chart = parse_xml(device.chart_file).getroot()
    states = {s.get("id"): s for s in chart if isinstance(s.tag, str) and s.tag in (f"{S}state", f"{S}final")}
    path = [t for _, steps in generated.device_paths(device.id) for t in steps]
    visits = [device.initial] + [t.target for t in path]
    ids = [f"p{n}_{state_id}" for n, state_id in enumerate(visits)]
    root = el("scxml", version="1.0", name=f"{device.id}-program", initial=ids[0])
    root.set(pnp_attr("device"), device.id)
    for n, state_id in enumerate(visits):
        last = n == len(visits) - 1
        state = el("final" if last else "state", id=ids[n])
        state.set(pnp_attr("deviceState"), state_id)
        concept = device.state(state_id).concept
        if concept:
            state.set(pnp_attr("concept"), concept_value(concept))
        onentry = states[state_id].find(f"{S}onentry")
        if onentry is not None:
            state.append(copy.deepcopy(onentry))
        if not last:
            state.append(_step(states[state_id], path[n], ids[n + 1]))
        root.append(state)
    return to_bytes(root)


def _step(source: etree._Element, transition: ChartTransition, target: str) -> etree._Element:
    """The chart's transition taken at this point, copied with a new target."""
    original = next(t for t in source.findall(f"{S}transition") if t.sourceline == transition.line)
    t = copy.deepcopy(original)
    t.set("target", target)
    return t
