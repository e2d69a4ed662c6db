"""Draw: pictures of state charts (a chart file, a device's chart, a generated chart) and the steps a task chart
runs, for ``pnp draw`` and the page."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.description.model import DeviceDescription

if TYPE_CHECKING:  # drawing loads graphviz: imported by the use cases that draw
    from plugnproduce.codegen.outputs import GeneratedChart
    from plugnproduce.drawing import PlanStep


def draw(chart: str | Path, output: str | Path, step: int | None = None) -> Path:
    """Draw a chart file into ``output`` (its suffix names the format); of a task chart, with ``step`` expanded."""
    from plugnproduce.drawing import draw_chart

    return draw_chart(chart, output, expand=step)


def picture_of_file(path: Path) -> bytes:
    """The SVG picture of a chart file."""
    from plugnproduce.drawing import render_chart

    return render_chart(path, "svg", path)


def device_chart(device: DeviceDescription) -> bytes:
    """The SCXML of the Device State Chart a device carries, as it would be written."""
    from plugnproduce.statechart import write_chart

    return write_chart(device.chart)


def picture_of_device(device: DeviceDescription) -> bytes:
    """The SVG picture of a device's Device State Chart (a discovered device's has no file on disk)."""
    from plugnproduce.drawing import render_chart

    return render_chart(device.chart, "svg", device.chart_file, name=Path(device.chart_file).stem)


def picture_of_chart(chart: GeneratedChart, step: int | None = None) -> bytes:
    """The SVG picture of a generated chart; of a task chart, with ``step`` (from 1) expanded."""
    from plugnproduce.drawing import render_chart
    from plugnproduce.statechart import parse_chart

    return render_chart(parse_chart(chart.data, chart.name), "svg", chart.name, name="chart", expand=step)


def task_steps(chart: GeneratedChart) -> tuple[PlanStep, ...]:
    """The steps a generated task chart runs, in order (none for a chart without a plan of processes)."""
    from plugnproduce.drawing import find_plan
    from plugnproduce.statechart import parse_chart

    plan = find_plan(parse_chart(chart.data, chart.name))
    return plan.steps if plan and plan.is_task else ()
