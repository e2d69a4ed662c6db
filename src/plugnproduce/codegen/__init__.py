"""Code generation (paper section 6): Specific Process State Charts, the Task State Chart,
the closed-world simulation chart and per-device programs, built as
:mod:`plugnproduce.statechart` model objects and written by its one writer."""

from __future__ import annotations

from plugnproduce.codegen.task import GeneratedTask, ImplausibleStep, generate_task

__all__ = ["GeneratedTask", "ImplausibleStep", "generate_task"]
