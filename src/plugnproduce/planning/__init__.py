"""The planning service: goals in, tasks out (:func:`plan`)."""

from plugnproduce.planning.planner import Plan, Unreachable, plan

__all__ = ["Plan", "Unreachable", "plan"]
