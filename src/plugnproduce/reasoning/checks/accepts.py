"""Parameter values no bound device takes: a finding, never a value silently dropped.

A process parameter goes to the device bound to its role, to the device command whose
``pnp:accepts`` names the parameter's quantity (or a quantity it subsumes). A value a task
gives for a parameter that no command of the bound device accepts would be lost at run
time; the check reports it at the value's line, naming the step, the parameter and the device.
"""

from __future__ import annotations

from collections.abc import Iterator

from plugnproduce.description.model import Cell, DeviceDescription, Parameter, Task
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
