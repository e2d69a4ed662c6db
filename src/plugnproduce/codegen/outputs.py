"""All charts code generation writes for a task, as named documents."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from plugnproduce.chartnames import STEP
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.codegen.projection import device_program
from plugnproduce.codegen.task import GeneratedTask, specific_name, values_data
from plugnproduce.description.model import Cell
from plugnproduce.statechart.io.writer import write_chart
from plugnproduce.statechart.model import Chart, Data, Final, Transition, pnp


@dataclass(frozen=True)
class GeneratedChart:
    """A generated document and the file name it is written under."""

    name: str
    kind: str
    """``specific``, ``task``, ``closed-world`` or ``device-program``."""
    data: bytes


def specific_charts(generated: GeneratedTask) -> list[GeneratedChart]:
    """The Specific Process State Charts: a step's process bound to its devices, written once for all the
    steps that share it (the task chart's step states name theirs in ``pnp:chart``)."""
    out = []
    for step in generated.bodies():
        index = step.step.index
        parallel = dataclasses.replace(step.element, children=[r.element for r in step.regions], extra_attrs={},
                                       transitions=[Transition(event=f"done.state.s{index}", targets=["done"])])
        root = Chart(name=f"s{index}-{step.process.id}", initial=[f"s{index}"], datamodel="python",
                     children=[parallel, Final(id="done")], extra_attrs={pnp("command"): step.process.id})
        if step.varying:  # values its other steps change: this chart runs with those of its first step
            root.data = [Data(id=STEP, expr="0"), values_data([step.varying])]
        out.append(GeneratedChart(specific_name(index, step.process.id), "specific", write_chart(root)))
    return out


def all_charts(generated: GeneratedTask, cell: Cell, per_device: bool = False) -> list[GeneratedChart]:
    """The specific process charts, the task chart, the closed-world chart and, if asked, device programs."""
    name = generated.task.name
    charts = specific_charts(generated)
    charts.append(GeneratedChart(f"{name}.task.scxml", "task", generated.task_chart()))
    charts.append(GeneratedChart(f"{name}.closed-world.scxml", "closed-world", closed_world_chart(generated, cell)))
    if per_device:
        used = sorted({r.device.id for s in generated.steps for r in s.regions})
        for device in used:
            charts.append(GeneratedChart(f"{name}.{device}.program.scxml", "device-program",
                                device_program(generated, cell.device(device))))
    return charts
