"""Parameter values no bound device takes: a finding, never a value silently dropped.

A process parameter goes to the device bound to its role, to the device command whose
``pnp:accepts`` names the parameter's quantity (or a quantity it subsumes). A value a task
gives for a parameter that no command of the bound device accepts would be lost at run
time; the check reports it at the value's line, naming the step, the parameter and the device.

A value whose device's chart does take its quantity, but not on the way the step walks the device from the
state it is in (the request taking it is not on that route), would be lost just the same: reported too
(``not_taken``), the route being code generation's own (:func:`plugnproduce.description.paths.find_path`).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from plugnproduce.description.model import Cell, DeviceDescription, Parameter, ProcessDescription, Role, Task
from plugnproduce.description.paths import NoPath, find_path, in_concept
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp.results import Problem, Reason, StepCheck


def accepts(device: DeviceDescription, quantity: str, taxonomy: Taxonomy) -> bool:
    """Whether some request of the device's chart carries ``quantity`` (or a more specific quantity)."""
    return any(taxonomy.is_a(q, quantity) or taxonomy.is_a(quantity, q)
               for t in device.transitions for q in t.accepts)


def not_accepted(task: Task, cell: Cell, steps: tuple[StepCheck, ...], parameters: dict[str, dict[str, Parameter]],
                 taxonomy: Taxonomy) -> Iterator[Problem]:
    """One problem per given parameter value whose bound device accepts no such quantity."""
    devices = {d.id: d for d in cell.devices}
    one_round = len(task.steps) // task.repeat
    for check, step in zip(steps[:one_round], task.steps[:one_round], strict=True):
        declared = parameters.get(step.command, {})
        for name in sorted(step.params):
            par = declared.get(name)
            device = devices.get(check.bindings.get(par.role, "")) if par else None
            if par is None or device is None or accepts(device, par.quantity, taxonomy):
                continue
            text = (f"step {step.index} ({step.command}): parameter {name} ({taxonomy.label(par.quantity)}) "
                    f"goes to device '{device.id}' (role '{par.role}'), but no command of its chart accepts "
                    f"{taxonomy.label(par.quantity)}; the value would be lost")
            reason = Reason("not_accepted", text, (par.quantity,), (par.where, device.where))
            yield Problem(step.index, step.command, "not_accepted", reason, task.where(step, name),
                          role=par.role, device=device.id, parameter=name)


def not_taken(task: Task, cell: Cell, steps: tuple[StepCheck, ...], processes: Mapping[str, ProcessDescription],
              taxonomy: Taxonomy) -> Iterator[Problem]:
    """One problem per given parameter value whose bound device takes its quantity, but not on the route the
    step's region walks it from the state it is in."""
    devices = {d.id: d for d in cell.devices}
    one_round = len(task.steps) // task.repeat
    routes: dict[tuple[str, str, str, str, frozenset[str]], tuple[str, ...]] = {}
    for check, step in zip(steps[:one_round], task.steps[:one_round], strict=True):
        process = processes.get(step.command)
        for role in process.roles if process else ():
            device = devices.get(check.bindings.get(role.name, ""))
            start = check.states.get(device.id) if device else None
            if process is None or device is None or start is None:
                continue
            given = frozenset(step.params)
            key = (device.id, process.id, role.name, start, given)  # all a route depends on: searched once each
            if key not in routes:
                routes[key] = tuple(_skipped(device, process, role, start, given, taxonomy))
            for name in routes[key]:
                par = process.parameter(name)
                label = taxonomy.label(par.quantity)
                text = (f"step {step.index} ({step.command}): parameter {name} ({label}) goes to device "
                        f"'{device.id}' (role '{role.name}'), but the route its chart takes from state '{start}' "
                        f"passes no command that accepts {label}; the value would be lost")
                reason = Reason("not_taken", text, (par.quantity,), (par.where, device.where))
                yield Problem(step.index, step.command, "not_taken", reason, task.where(step, name),
                              role=role.name, device=device.id, state=start, parameter=name)


def _skipped(device: DeviceDescription, process: ProcessDescription, role: Role, start: str, given: frozenset[str],
             taxonomy: Taxonomy) -> list[str]:
    """The given parameters of ``role`` that the device's chart takes somewhere, but whose leg of the region's
    route (code generation's) passes no request taking them."""
    out: list[str] = []
    current = start
    state = next((s for s in device.states if s.id == start), None)
    if state is None or not in_concept(state, role.start_concept, taxonomy):
        return out  # a device in the wrong state is the plausibility check's finding; its route is not this one
    for general in role.region[1:]:
        wanted = frozenset(process.parameter(p).quantity for p in general.params)
        try:
            path = find_path(device, current, general.concept, taxonomy, wanted)
        except (NoPath, KeyError):
            return out  # a route that does not exist is the plausibility check's finding
        for name in (p for p in general.params if p in given):
            quantity = process.parameter(name).quantity
            on_route = any(taxonomy.is_a(q, quantity) or taxonomy.is_a(quantity, q)
                           for t in path.steps if t.request for q in t.accepts)
            if not on_route and accepts(device, quantity, taxonomy):
                out.append(name)
        current = path.target
    return out
