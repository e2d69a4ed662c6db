"""What a simulated OPC UA device publishes, read from its description and chart (the naming rule of
:mod:`plugnproduce.protocols.opcua.spec`)."""

from __future__ import annotations

from plugnproduce.description.model import DeviceDescription
from plugnproduce.description.quantities.reports import reported_values
from plugnproduce.ontology.iris import local_name
from plugnproduce.protocols.opcua.spec import ArgumentSpec, MethodSpec, NodeSpec, kind_of
from plugnproduce.sim.payloads import event_payloads


def node_spec(device: DeviceDescription) -> NodeSpec:
    """One method per request the chart waits for (input arguments: the quantities it carries, typed by the
    device's declared arguments; output arguments: the values of the event it answers with at once), and one
    event type per event the chart sends (fields: the values it carries)."""
    payloads = event_payloads(device)
    inputs: dict[str, list[str]] = {}
    events: dict[str, tuple[str, ...]] = {}
    for t in (*device.transitions, *device.stops):
        if t.request is not None:
            quantities = inputs.setdefault(t.request.name, [])
            quantities.extend(q for q in t.accepts if q not in quantities)
        for c in t.sends:
            if c.kind == "event":
                events[c.name] = tuple(payloads.get(c.name, ()))
    methods = []
    for request, quantities in inputs.items():
        answer = device.answer_to(request)
        methods.append(MethodSpec(
            request,
            tuple(ArgumentSpec(local_name(q), kind_of(device.argument(request, q).datatype)) for q in quantities),
            tuple(payloads.get(answer, ())) if answer is not None else ()))
    return NodeSpec(device.id, tuple(methods), events, reported_variables(device))


def reported_variables(device: DeviceDescription) -> tuple[ArgumentSpec, ...]:
    """One variable per value the chart says the device reports with its state, typed as the device's requests
    take that quantity (a pose ``Double[6]``; a quantity no request takes: any)."""
    out = []
    for quantity in sorted(reported_values(device)):
        datatypes = [a.datatype for a in device.arguments if local_name(a.quantity) == quantity and a.datatype]
        out.append(ArgumentSpec(quantity, kind_of(datatypes[0]) if datatypes else "any"))
    return tuple(out)
