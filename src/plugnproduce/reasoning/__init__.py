"""Reasoning with clingo: offered process commands, plausibility, repairs, why-not answers, batches.

Descriptions become ASP facts through one typed boundary (:mod:`.terms`, :mod:`.schema`,
:mod:`.facts`); the encodings in ``rules/`` decide; answers come back as dataclasses
(:mod:`.results`) whose reasons name the ontology terms and the ``file:line`` they rest on.
Infeasible and implausible are results, never exceptions.
"""

from __future__ import annotations

from plugnproduce.reasoning.batches import CSV_HEADER as BATCH_CSV_HEADER
from plugnproduce.reasoning.batches import BatchRow, Configuration, batch, generate, read_configurations
from plugnproduce.reasoning.contracts import normalised
from plugnproduce.reasoning.offers import capabilities, explain_process
from plugnproduce.reasoning.plausibility import check, explain_step
from plugnproduce.reasoning.repairs import repair
from plugnproduce.reasoning.results import (
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

__all__ = [
    "normalised",
    "BATCH_CSV_HEADER",
    "BatchRow",
    "Capabilities",
    "CheckResult",
    "Configuration",
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
    "batch",
    "capabilities",
    "check",
    "explain_process",
    "explain_step",
    "generate",
    "read_configurations",
    "repair",
]
