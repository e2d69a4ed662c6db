"""Reasoning with clingo: offered process commands, plausibility, repairs, why-not answers, batches.

Descriptions become ASP facts through one typed boundary (:mod:`.terms`, :mod:`.schema`,
:mod:`.facts`); the encodings in ``rules/`` decide; answers come back as dataclasses
(:mod:`.results`) whose reasons name the ontology terms and the ``file:line`` they rest on.
Infeasible and implausible are results, never exceptions.
"""

from __future__ import annotations

from plugnproduce.reasoning.axioms import ontology_of
from plugnproduce.reasoning.batches import CSV_HEADER as BATCH_CSV_HEADER
from plugnproduce.reasoning.batches import (
    BatchRow,
    Configuration,
    Engine,
    batch,
    bounded_lines,
    configurations_from,
    engine,
    generate,
    read_configurations,
    report,
    report_from,
)
from plugnproduce.reasoning.cluster import check_address as check_cluster_address
from plugnproduce.reasoning.cluster import cluster_mapper
from plugnproduce.reasoning.clusterpeer import ClusterAccess, ClusterError
from plugnproduce.reasoning.contracts import normalised
from plugnproduce.reasoning.counterfactuals import Counterfactual
from plugnproduce.reasoning.counterfactuals import from_repairs as counterfactuals_from_repairs
from plugnproduce.reasoning.derivation import Node
from plugnproduce.reasoning.offers import capabilities, explain_process
from plugnproduce.reasoning.plausibility import check, explain_step
from plugnproduce.reasoning.purchases import Purchase
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
from plugnproduce.reasoning.sideeffects import AssessedRepair, SideEffect, assess
from plugnproduce.reasoning.why import Explanation, explain_offered, explain_plausible
from plugnproduce.reasoning.windows import repair

__all__ = [
    "Engine",
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
    "BATCH_CSV_HEADER",
    "BatchRow",
    "Capabilities",
    "CheckResult",
    "Configuration",
    "Edit",
    "NotOffered",
    "Offer",
    "Problem",
    "Purchase",
    "ProcessExplanation",
    "Reason",
    "Repair",
    "RepairCosts",
    "StepCheck",
    "StepExplanation",
    "batch",
    "capabilities",
    "check",
    "check_cluster_address",
    "ClusterAccess",
    "ClusterError",
    "bounded_lines",
    "cluster_mapper",
    "configurations_from",
    "engine",
    "explain_process",
    "explain_step",
    "generate",
    "read_configurations",
    "repair",
    "report",
    "report_from",
]
