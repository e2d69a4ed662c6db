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
