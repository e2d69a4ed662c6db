"""Code generation (paper section 6): Specific Process State Charts, the Task State Chart,
the closed-world simulation chart and per-device programs, all W3C SCXML."""

from __future__ import annotations

from plugnproduce.codegen.paths import NoPath, find_path
from plugnproduce.codegen.task import DONE, FAILED, GeneratedTask, ImplausibleStep, generate_task

__all__ = ["DONE", "FAILED", "GeneratedTask", "ImplausibleStep", "NoPath", "find_path", "generate_task"]
