"""Reasoning with clingo: offered process commands, plausibility, repairs, why-not answers.

Descriptions become ASP facts through one typed boundary (:mod:`.asp.terms`, :mod:`.asp.schema`,
:mod:`.asp.facts`); the encodings in ``rules/`` decide; answers come back as dataclasses
(:mod:`.asp.results`) whose reasons name the ontology terms and the ``file:line`` they rest on.
Infeasible and implausible are results, never exceptions.

The layer is split by concern, each part using only those before it:

- :mod:`.asp`: the ASP layer (the solver, the fact schema, facts in, answers and reasons out);
- :mod:`.checks`: what a cell offers and whether a task is plausible on it;
- :mod:`.repairs`: the cheapest repairs of an implausible task and their side effects;
- :mod:`.explanation`: why and why not, down to the axioms and rules, and counterfactuals.

The batch over many cells (:mod:`plugnproduce.batch`) uses this layer and is not part of it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from plugnproduce.reasoning.asp.derivation import Node
    from plugnproduce.reasoning.asp.results import (
        Capabilities,
        CheckResult,
        Edit,
        NotOffered,
        Offer,
        Problem,
        ProcessExplanation,
        Reason,
        Repair,
        RepairCosts,
        StepCheck,
        StepExplanation,
    )
    from plugnproduce.reasoning.checks.contracts import normalised
    from plugnproduce.reasoning.checks.offers import capabilities, explain_process
    from plugnproduce.reasoning.checks.plausibility import check, explain_step
    from plugnproduce.reasoning.explanation.axioms import ontology_of
    from plugnproduce.reasoning.explanation.counterfactuals import Counterfactual
    from plugnproduce.reasoning.explanation.counterfactuals import from_repairs as counterfactuals_from_repairs
    from plugnproduce.reasoning.explanation.why import Explanation, explain_offered, explain_plausible
    from plugnproduce.reasoning.repairs.sideeffects import AssessedRepair, SideEffect, assess
    from plugnproduce.reasoning.repairs.windows import repair

_WHERE: dict[str, tuple[str, str]] = {
    "assess": ("repairs.sideeffects", "assess"),
    "AssessedRepair": ("repairs.sideeffects", "AssessedRepair"),
    "Capabilities": ("asp.results", "Capabilities"),
    "capabilities": ("checks.offers", "capabilities"),
    "check": ("checks.plausibility", "check"),
    "CheckResult": ("asp.results", "CheckResult"),
    "Counterfactual": ("explanation.counterfactuals", "Counterfactual"),
    "counterfactuals_from_repairs": ("explanation.counterfactuals", "from_repairs"),
    "Edit": ("asp.results", "Edit"),
    "explain_offered": ("explanation.why", "explain_offered"),
    "explain_plausible": ("explanation.why", "explain_plausible"),
    "explain_process": ("checks.offers", "explain_process"),
    "explain_step": ("checks.plausibility", "explain_step"),
    "Explanation": ("explanation.why", "Explanation"),
    "Node": ("asp.derivation", "Node"),
    "normalised": ("checks.contracts", "normalised"),
    "NotOffered": ("asp.results", "NotOffered"),
    "Offer": ("asp.results", "Offer"),
    "ontology_of": ("explanation.axioms", "ontology_of"),
    "Problem": ("asp.results", "Problem"),
    "ProcessExplanation": ("asp.results", "ProcessExplanation"),
    "Reason": ("asp.results", "Reason"),
    "Repair": ("asp.results", "Repair"),
    "repair": ("repairs.windows", "repair"),
    "RepairCosts": ("asp.results", "RepairCosts"),
    "SideEffect": ("repairs.sideeffects", "SideEffect"),
    "StepCheck": ("asp.results", "StepCheck"),
    "StepExplanation": ("asp.results", "StepExplanation"),
}
"""Each name this package offers: the module it is defined in (below this package) and its name there."""


def __getattr__(name: str) -> object:
    """Import the module that defines ``name`` on its first use (:pep:`562`), so that importing the package loads
    neither clingo nor owlready2 nor any of its parts."""
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, attr = _WHERE[name]
    value = getattr(importlib.import_module(f"{__name__}.{module}"), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_WHERE})


__all__ = [
    "AssessedRepair",
    "Counterfactual",
    "Explanation",
    "Node",
    "SideEffect",
    "assess",
    "counterfactuals_from_repairs",
    "explain_offered",
    "explain_plausible",
    "normalised",
    "ontology_of",
    "Capabilities",
    "CheckResult",
    "Edit",
    "NotOffered",
    "Offer",
    "Problem",
    "ProcessExplanation",
    "Reason",
    "Repair",
    "RepairCosts",
    "StepCheck",
    "StepExplanation",
    "capabilities",
    "check",
    "explain_process",
    "explain_step",
    "repair",
]
