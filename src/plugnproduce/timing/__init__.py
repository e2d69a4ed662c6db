"""Cycle time: how long devices take for their requests, and what that makes of a process, a step and a task.

:mod:`~plugnproduce.timing.requests` times one device's requests (its chart's delays or its declared
durations; the simulated devices use it, so it imports nothing of code generation),
:mod:`~plugnproduce.timing.estimate` follows each step's Specific Process State Chart (parallel regions overlap;
the critical path counts) and sums the steps of a task, :mod:`~plugnproduce.timing.tasks` checks, generates and
estimates a task in a cell, :mod:`~plugnproduce.timing.kept` keeps the estimate in the cache folder.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names

if TYPE_CHECKING:
    from plugnproduce.timing.requests import DeviceTimer, chart_delays

__getattr__, __dir__ = lazy_names(__name__, dict.fromkeys(("DeviceTimer", "chart_delays"), ".requests"))

__all__ = ["DeviceTimer", "chart_delays"]
