"""The use cases behind every interface (CLI, HTTP API, notebooks).

Functions here load descriptions, call the concepts (validation, reasoning, code
generation, execution) and return typed results; they never print. One module per
group of use cases, every name here:

- :mod:`.descriptions`: knowledge and descriptions (load, read, validate, impact, export);
- :mod:`.checks`: capabilities, check and repair;
- :mod:`.explanations`: why a command is offered, why a step is plausible;
- :mod:`.goals`: planning from a goal;
- :mod:`.batches`: the feasibility of many configurations;
- :mod:`.programs`: generate and verify, and what a run needs (:func:`plan_run`);
- :mod:`.journals`: the runs folder and past runs' journals;
- :mod:`.resumes`: what runs on after a stopped run, planned from the devices' states;
- :mod:`.teaching`: teach-in, a value a device reports held to its contracts.

- :mod:`.drawings`: pictures of state charts.

Running a task on devices (discovery, the executor) is the controller's
(:mod:`plugnproduce.controller`).

The faces import the service and the controller, never a concept package: the concepts' types and
helpers they name (a task, a cell, a check's result, a verification budget ...) are named here too,
all of them imported on first use (:data:`_ELSEWHERE`), so that ``pnp --help`` loads none of them and a command
only the use cases it calls.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_module, lazy_names

if TYPE_CHECKING:
    from plugnproduce import reasoning
    from plugnproduce.batch import (
        BATCH_CSV_HEADER,
        ClusterAccess,
        Configuration,
        Engine,
        bounded_lines,
        check_cluster_address,
        configurations_from,
        read_configurations,
    )
    from plugnproduce.batch import generate as random_configurations
    from plugnproduce.codegen import GeneratedTask, ImplausibleStep
    from plugnproduce.codegen.outputs import GeneratedChart
    from plugnproduce.deferred import make_all_classes
    from plugnproduce.description.flow import Loop
    from plugnproduce.description.model import (
        Cell,
        DeviceDescription,
        Link,
        Output,
        Parameter,
        ProcessDescription,
        Step,
        Task,
        plain_value,
    )
    from plugnproduce.executor.journal import describe
    from plugnproduce.knowledge import Knowledge, Library
    from plugnproduce.knowledge.vocab import taxonomy_tree, vocabulary, vocabulary_text, vocabulary_tree
    from plugnproduce.ontology.export import FORMATS as ONTOLOGY_FORMATS
    from plugnproduce.ontology.iris import concept_value, local_name
    from plugnproduce.ontology.taxonomy import Taxonomy
    from plugnproduce.planning import Plan, Unreachable
    from plugnproduce.reasoning import CheckResult, Explanation, Reason
    from plugnproduce.resources import rules_path
    from plugnproduce.safeio import MAX_BYTES, MAX_DIGITS
    from plugnproduce.service.batches import (
        batch,
        batch_cycle_times,
        batch_engine,
        batch_report,
        batch_report_from,
        generate_configurations,
        pareto_front,
    )
    from plugnproduce.service.checks import (
        MORE_REPAIRS,
        assessed_repairs,
        capabilities,
        catalogue_players,
        check,
        repair,
    )
    from plugnproduce.service.descriptions import (
        CellArg,
        DeviceView,
        TaskArg,
        as_task,
        builtin,
        catalogue,
        cell,
        cell_and_knowledge,
        device_view,
        export_ontology,
        impact,
        knowledge,
        knowledge_for_cell,
        task,
        task_from_text,
        task_text,
        validate,
        validate_tasks,
    )
    from plugnproduce.service.explanations import explain_offered, explain_plausible, explain_process, explain_step
    from plugnproduce.service.goals import goal_findings, goal_from_text, plan, plan_pddl
    from plugnproduce.service.journals import new_run_id, report, runs, runs_folder
    from plugnproduce.service.programs import (
        Generated,
        Generation,
        ImplausibleTask,
        Unverified,
        cycle_time,
        generate,
        generation,
        plan_run,
        repair_cycle_times,
        verify,
    )
    from plugnproduce.service.resumes import NotResumable, NoWayOn, Replan, Stopped, replan, rest_of_task, stopped_run
    from plugnproduce.service.teaching import ReportsNothing, Taught, judge_taught, reported_quantities, reported_value
    from plugnproduce.timing.cycle import CycleTime
    from plugnproduce.verification import Budget, Verification
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner

_ELSEWHERE = {
    "Loop": "plugnproduce.description.flow",
    "make_all_classes": "plugnproduce.deferred",
    **dict.fromkeys(("Cell", "DeviceDescription", "Link", "Output", "Parameter", "ProcessDescription", "Step",
                     "Task", "plain_value"), "plugnproduce.description.model"),
    "describe": "plugnproduce.executor.journal",
    **dict.fromkeys(("Knowledge", "Library"), "plugnproduce.knowledge"),
    **dict.fromkeys(("batch", "batch_cycle_times", "batch_engine", "batch_report", "batch_report_from",
                     "generate_configurations", "pareto_front"), "plugnproduce.service.batches"),
    **dict.fromkeys(("MORE_REPAIRS", "assessed_repairs", "capabilities", "catalogue_players", "check", "repair"),
                    "plugnproduce.service.checks"),
    **dict.fromkeys(("CellArg", "DeviceView", "TaskArg", "as_task", "builtin", "catalogue", "cell",
                     "cell_and_knowledge", "device_view", "export_ontology", "impact", "knowledge",
                     "knowledge_for_cell", "task", "task_from_text", "task_text", "validate", "validate_tasks"),
                    "plugnproduce.service.descriptions"),
    **dict.fromkeys(("explain_offered", "explain_plausible", "explain_process", "explain_step"),
                    "plugnproduce.service.explanations"),
    **dict.fromkeys(("goal_findings", "goal_from_text", "plan", "plan_pddl"), "plugnproduce.service.goals"),
    **dict.fromkeys(("new_run_id", "report", "runs", "runs_folder"), "plugnproduce.service.journals"),
    **dict.fromkeys(("Generated", "Generation", "ImplausibleTask", "Unverified", "cycle_time", "generate",
                     "generation", "plan_run", "repair_cycle_times", "verify"), "plugnproduce.service.programs"),
    **dict.fromkeys(("NotResumable", "NoWayOn", "Replan", "Stopped", "replan", "rest_of_task", "stopped_run"),
                    "plugnproduce.service.resumes"),
    **dict.fromkeys(("ReportsNothing", "Taught", "judge_taught", "reported_quantities", "reported_value"),
                    "plugnproduce.service.teaching"),
    **dict.fromkeys(("GeneratedTask", "ImplausibleStep"), "plugnproduce.codegen"),
    "GeneratedChart": "plugnproduce.codegen.outputs",
    **dict.fromkeys(("taxonomy_tree", "vocabulary", "vocabulary_text", "vocabulary_tree"),
                    "plugnproduce.knowledge.vocab"),
    "ONTOLOGY_FORMATS": "plugnproduce.ontology.export:FORMATS",
    "Taxonomy": "plugnproduce.ontology.taxonomy",
    **dict.fromkeys(("concept_value", "local_name"), "plugnproduce.ontology.iris"),
    **dict.fromkeys(("Plan", "Unreachable"), "plugnproduce.planning"),
    "CycleTime": "plugnproduce.timing.cycle",
    **dict.fromkeys(("BATCH_CSV_HEADER", "ClusterAccess", "Configuration", "Engine", "bounded_lines",
                     "check_cluster_address",
                     "configurations_from", "read_configurations"), "plugnproduce.batch"),
    "random_configurations": "plugnproduce.batch:generate",
    **dict.fromkeys(("CheckResult", "Explanation", "Reason"), "plugnproduce.reasoning"),
    "rules_path": "plugnproduce.resources",
    **dict.fromkeys(("MAX_BYTES", "MAX_DIGITS"), "plugnproduce.safeio"),
    **dict.fromkeys(("Budget", "Verification"), "plugnproduce.verification"),
}
"""Every name the service gives, imported from its module on first use: name → module (``module:name`` when the
service names it otherwise). A command loads only the use cases it calls: ``pnp capabilities`` none of the batch,
the planner, the journals or code generation."""


__getattr__, __dir__ = lazy_names(__name__, _ELSEWHERE)

__all__ = [
    "BATCH_CSV_HEADER",
    "MAX_BYTES",
    "MAX_DIGITS",
    "make_all_classes",
    "repair_cycle_times",
    "batch_cycle_times",
    "pareto_front",
    "cycle_time",
    "MORE_REPAIRS",
    "ONTOLOGY_FORMATS",
    "Budget",
    "Cell",
    "CellArg",
    "CheckResult",
    "ClusterAccess",
    "Configuration",
    "CycleTime",
    "Engine",
    "DeviceDescription",
    "DeviceView",
    "Explanation",
    "Generated",
    "GeneratedChart",
    "GeneratedTask",
    "Generation",
    "ImplausibleStep",
    "ImplausibleTask",
    "NoWayOn",
    "NotResumable",
    "Replan",
    "ReportsNothing",
    "Stopped",
    "Taught",
    "Knowledge",
    "Library",
    "Link",
    "Loop",
    "Output",
    "Parameter",
    "Plan",
    "ProcessDescription",
    "Reason",
    "Step",
    "Task",
    "TaskArg",
    "Taxonomy",
    "Unreachable",
    "Unverified",
    "Verification",
    "as_task",
    "assessed_repairs",
    "batch",
    "batch_engine",
    "batch_report",
    "batch_report_from",
    "bounded_lines",
    "builtin",
    "capabilities",
    "catalogue",
    "catalogue_players",
    "cell",
    "cell_and_knowledge",
    "check",
    "check_cluster_address",
    "concept_value",
    "configurations_from",
    "describe",
    "device_view",
    "explain_offered",
    "explain_plausible",
    "explain_process",
    "explain_step",
    "export_ontology",
    "generate",
    "generate_configurations",
    "generation",
    "goal_findings",
    "goal_from_text",
    "impact",
    "judge_taught",
    "knowledge",
    "knowledge_for_cell",
    "local_name",
    "new_run_id",
    "plain_value",
    "plan",
    "plan_pddl",
    "plan_run",
    "random_configurations",
    "read_configurations",
    "reasoning",
    "repair",
    "replan",
    "report",
    "reported_quantities",
    "reported_value",
    "rest_of_task",
    "rules_path",
    "runs",
    "runs_folder",
    "stopped_run",
    "task",
    "task_from_text",
    "task_text",
    "taxonomy_tree",
    "validate",
    "validate_tasks",
    "verify",
    "vocabulary",
    "vocabulary_text",
    "vocabulary_tree",
]
