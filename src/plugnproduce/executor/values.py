"""Values that flow between steps, for the journal: where each was produced and where it was used.

A step's output that a later step takes (``pick_pose: {from: localize, output: part_pose}``)
is journalled twice as a ``value`` record: ``produced`` when the device's event brings it,
``used`` when a request carries it to the consuming step's device.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from plugnproduce.chartnames import OUTCOME, output_variable
from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.ontology.iris import local_name


def produced(generated: GeneratedTask, step: int | None, device: str,
             values: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The outputs (and the outcome) a device event at step position ``step`` brings."""
    if step is None or not 1 <= step <= len(generated.steps):
        return []
    s = generated.steps[step - 1]
    return [{"value": output if variable == OUTCOME else f"{s.step.name}.{output}", "produced": values[output],
             "step": step, "device": device}
            for role, output, variable in s.produces if s.binding.get(role) == device and output in values]


def used(generated: GeneratedTask, step: int | None, device: str, params: Mapping[str, Any],
         datamodel: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The earlier steps' outputs a request at step position ``step`` carries."""
    if step is None or not 1 <= step <= len(generated.steps):
        return []
    s = generated.steps[step - 1]
    out = []
    for name, link in sorted(s.step.links().items()):
        parameter = s.process.parameter(name)
        carried = local_name(parameter.quantity)
        variable = output_variable(link.step, link.output)
        if s.binding.get(parameter.role) == device and carried in params and \
                params[carried] == link.applied(datamodel.get(variable)):
            out.append({"value": f"{link.step}.{link.output}", "used": params[carried], "step": step,
                        "device": device, "parameter": name})
    return out
