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

Running a task on devices (discovery, the executor) is the controller's
(:mod:`plugnproduce.controller`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.knowledge import Knowledge, Library
from plugnproduce.lazy import lazy_module
from plugnproduce.service.batches import (
    batch,
    batch_engine,
    batch_report,
    batch_report_from,
    generate_configurations,
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
from plugnproduce.service.goals import goal_from_text, plan, plan_pddl
from plugnproduce.service.journals import new_run_id, report, runs, runs_folder
from plugnproduce.service.programs import (
    Generated,
    Generation,
    ImplausibleTask,
    Unverified,
    generate,
    generation,
    plan_run,
    verify,
)
from plugnproduce.service.resumes import NotResumable, NoWayOn, Replan, Stopped, replan, rest_of_task, stopped_run
from plugnproduce.service.teaching import ReportsNothing, Taught, judge_taught, reported_quantities, reported_value

if TYPE_CHECKING:
    from plugnproduce import reasoning
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner

__all__ = [
    "MORE_REPAIRS",
    "Cell",
    "CellArg",
    "DeviceDescription",
    "DeviceView",
    "Generated",
    "Generation",
    "ImplausibleTask",
    "NoWayOn",
    "NotResumable",
    "Replan",
    "ReportsNothing",
    "Stopped",
    "Taught",
    "Knowledge",
    "Library",
    "Task",
    "TaskArg",
    "Unverified",
    "as_task",
    "assessed_repairs",
    "batch",
    "batch_engine",
    "batch_report",
    "batch_report_from",
    "builtin",
    "capabilities",
    "catalogue",
    "catalogue_players",
    "cell",
    "cell_and_knowledge",
    "check",
    "device_view",
    "explain_offered",
    "explain_plausible",
    "explain_process",
    "explain_step",
    "export_ontology",
    "generate",
    "generate_configurations",
    "generation",
    "goal_from_text",
    "impact",
    "judge_taught",
    "knowledge",
    "knowledge_for_cell",
    "new_run_id",
    "plan",
    "plan_pddl",
    "plan_run",
    "reasoning",
    "repair",
    "replan",
    "report",
    "reported_quantities",
    "reported_value",
    "rest_of_task",
    "runs",
    "runs_folder",
    "stopped_run",
    "task",
    "task_from_text",
    "task_text",
    "validate",
    "validate_tasks",
    "verify",
]
