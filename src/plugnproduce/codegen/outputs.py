"""All charts code generation writes for a task, as named documents."""

from __future__ import annotations

import copy
from dataclasses import dataclass

from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.codegen.emit import el, pnp_attr, to_bytes
from plugnproduce.codegen.projection import device_program
from plugnproduce.codegen.task import GeneratedTask
from plugnproduce.description.model import Cell


@dataclass(frozen=True)
class Chart:
    """A generated document and the file name it is written under."""

    name: str
    kind: str
    """``specific``, ``task``, ``closed-world`` or ``device-program``."""
    data: bytes


def specific_charts(generated: GeneratedTask) -> list[Chart]:
    """One Specific Process State Chart per step: its process bound to the step's devices."""
    out = []
    for step in generated.steps:
        index = step.step.index
        root = el("scxml", version="1.0", datamodel="python", initial=f"s{index}",
                  name=f"s{index}-{step.process.id}")
        root.set(pnp_attr("command"), step.process.id)
        parallel = el("parallel", id=f"s{index}")
        for region in step.regions:
            parallel.append(copy.deepcopy(region.element))
        parallel.append(el("transition", event=f"done.state.s{index}", target="done"))
        root.append(parallel)
        root.append(el("final", id="done"))
        out.append(Chart(f"step{index:02d}-{step.process.id}.scxml", "specific", to_bytes(root)))
    return out


def all_charts(generated: GeneratedTask, cell: Cell, per_device: bool = False) -> list[Chart]:
    """The specific process charts, the task chart, the closed-world chart and, if asked, device programs."""
    name = generated.task.name
    charts = specific_charts(generated)
    charts.append(Chart(f"{name}.task.scxml", "task", generated.task_chart()))
    charts.append(Chart(f"{name}.closed-world.scxml", "closed-world", closed_world_chart(generated, cell)))
    if per_device:
        used = sorted({r.device.id for s in generated.steps for r in s.regions})
        for device in used:
            charts.append(Chart(f"{name}.{device}.program.scxml", "device-program",
                                device_program(generated, cell.device(device))))
    return charts
