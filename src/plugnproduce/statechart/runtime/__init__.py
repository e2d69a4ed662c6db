"""The SCXML runtime: compiles a :class:`~plugnproduce.statechart.model.Chart` and runs it."""

from __future__ import annotations
