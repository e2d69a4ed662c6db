"""Pictures of state charts: device, process, task, closed-world charts and device programs,
drawn with Graphviz from the chart model."""

from __future__ import annotations

from plugnproduce.drawing.charts import COLUMN, SHOWN, column_length, shown_steps, step_node
from plugnproduce.drawing.render import FORMATS, Layout, chart_to_dot, draw_chart, layout, render_chart, run_dot
from plugnproduce.drawing.steps import Plan, PlanStep, find_plan

__all__ = ["COLUMN", "FORMATS", "SHOWN", "Layout", "Plan", "PlanStep", "chart_to_dot", "column_length", "draw_chart",
           "find_plan", "layout", "render_chart", "run_dot", "shown_steps", "step_node"]
