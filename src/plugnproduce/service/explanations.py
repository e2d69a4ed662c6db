"""Explain: why a process command is (not) offered, why a step is (not) plausible."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.description.model import DeviceDescription
from plugnproduce.knowledge import Knowledge
from plugnproduce.lazy import lazy_module
from plugnproduce.service.checks import assessed_repairs
from plugnproduce.service.descriptions import CellArg, TaskArg, _devices, as_task, cell_and_knowledge

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce import reasoning
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner


def explain_process(cell_or_path: CellArg, command: str,
                    knowledge: Knowledge | None = None) -> reasoning.ProcessExplanation:
    """Why a process command is (not) offered in a cell."""
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    return reasoning.explain_process(the_cell, command, k)


def explain_step(task_or_path: TaskArg, cell_or_path: CellArg, n: int,
                 knowledge: Knowledge | None = None) -> reasoning.StepExplanation:
    """Why step ``n`` (1-based) of a task is (not) plausible in a cell."""
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    return reasoning.explain_step(as_task(task_or_path), the_cell, n, k)


def explain_offered(cell_or_path: CellArg, command: str, knowledge: Knowledge | None = None,
                    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
                    language: str = "en") -> reasoning.Explanation:
    """Why a process command is (not) offered: the derivation tree (rules, ontology axioms, chart states) and
    the counterfactuals the reasoner confirms (devices of the catalogue to add or swap in; for a "yes", the
    devices it rests on)."""
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    ontology = reasoning.ontology_of(k.ontology_files(), k.taxonomy)
    return reasoning.explain_offered(command, the_cell, k, ontology,
                                     _devices(catalogue_or_folder, k), language)


def explain_plausible(task_or_path: TaskArg, cell_or_path: CellArg, n: int, knowledge: Knowledge | None = None,
                      language: str = "en") -> reasoning.Explanation:
    """Why step ``n`` (1-based) of a task is (not) plausible: the derivation tree and, for a "no", the states its
    devices would have to be in and the repairs (steps to insert, remove or reorder, with their side effects),
    each confirmed by the reasoner."""
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    the_task = as_task(task_or_path)
    ontology = reasoning.ontology_of(k.ontology_files(), k.taxonomy)
    ex = reasoning.explain_plausible(the_task, n, the_cell, k, ontology, language)
    if ex.answer:
        return ex
    edits = reasoning.counterfactuals_from_repairs(assessed_repairs(the_task, the_cell, None, 3, k))
    return dataclasses.replace(ex, counterfactuals=ex.counterfactuals + tuple(edits),
                               none_exists=None if ex.counterfactuals or edits else ex.none_exists)
