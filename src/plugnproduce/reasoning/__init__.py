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

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names

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

_WHERE: dict[str, str] = {
    "assess": ".repairs.sideeffects",
    "AssessedRepair": ".repairs.sideeffects",
    "Capabilities": ".asp.results",
    "capabilities": ".checks.offers",
    "check": ".checks.plausibility",
    "CheckResult": ".asp.results",
    "Counterfactual": ".explanation.counterfactuals",
    "counterfactuals_from_repairs": ".explanation.counterfactuals:from_repairs",
    "Edit": ".asp.results",
    "explain_offered": ".explanation.why",
    "explain_plausible": ".explanation.why",
    "explain_process": ".checks.offers",
    "explain_step": ".checks.plausibility",
    "Explanation": ".explanation.why",
    "Node": ".asp.derivation",
    "normalised": ".checks.contracts",
    "NotOffered": ".asp.results",
    "Offer": ".asp.results",
    "ontology_of": ".explanation.axioms",
    "Problem": ".asp.results",
    "ProcessExplanation": ".asp.results",
    "Reason": ".asp.results",
    "Repair": ".asp.results",
    "repair": ".repairs.windows",
    "RepairCosts": ".asp.results",
    "SideEffect": ".repairs.sideeffects",
    "StepCheck": ".asp.results",
    "StepExplanation": ".asp.results",
}
"""Each name this package offers: the module it is defined in (below this package) and its name there."""


__getattr__, __dir__ = lazy_names(__name__, _WHERE)  # loads neither clingo nor owlready2 nor any part until used


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
