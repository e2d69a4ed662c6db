"""Cycle time: how long devices take for their requests, and what that makes of a process, a step and a task.

:mod:`~plugnproduce.timing.requests` times one device's requests (its chart's delays or its declared
durations), :mod:`~plugnproduce.timing.estimate` follows each step's Specific Process State Chart (parallel
regions overlap; the critical path counts) and sums the steps of a task.
"""

from __future__ import annotations

from plugnproduce.timing.estimate import CycleTime, StepTime, estimate_task
from plugnproduce.timing.requests import DeviceTimer, chart_delays

__all__ = ["CycleTime", "DeviceTimer", "StepTime", "chart_delays", "estimate_task"]
