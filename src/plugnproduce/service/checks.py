"""Check and repair: the process commands a cell offers, whether a task is plausible in it, and the cheapest
repairs of a task that is not."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.description.model import DeviceDescription
from plugnproduce.knowledge import Knowledge
from plugnproduce.lazy import lazy_module
from plugnproduce.service.descriptions import CellArg, TaskArg, _devices, _k, as_task, cell_and_knowledge

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce import reasoning
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner


def capabilities(cell_or_path: CellArg, knowledge: Knowledge | None = None,
                 all_bindings: bool = False) -> reasoning.Capabilities:
    """The process commands a cell offers, each with one valid role binding, how many there are and the
    devices that can fill each role (every binding listed if ``all_bindings``); the others with reasons."""
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    return reasoning.capabilities(the_cell, k, all_bindings)


def check(task_or_path: TaskArg, cell_or_path: CellArg, knowledge: Knowledge | None = None) -> reasoning.CheckResult:
    """Whether a task is plausible in a cell: per step its bindings, device states and problems."""
    from plugnproduce.reasoning.checks.linksafety import link_safety

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    task = as_task(task_or_path)
    result = reasoning.check(task, the_cell, k)
    return dataclasses.replace(result, links=link_safety(task, the_cell, result, k))


def repair(
    task_or_path: TaskArg,
    cell_or_path: CellArg,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    top: int = 3,
    costs: reasoning.RepairCosts | None = None,
    knowledge: Knowledge | None = None,
) -> list[reasoning.Repair]:
    """The ``top`` cheapest distinct repairs of an implausible task (none if it is plausible).

    With a catalogue (device descriptions, or a folder of them) a repair may add a device.
    """
    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    devices = None if catalogue_or_folder is None else _devices(catalogue_or_folder, k)
    return reasoning.repair(as_task(task_or_path), the_cell, k,
                            catalogue=devices, top=top, costs=costs)


def catalogue_players(result: reasoning.CheckResult,
                      knowledge: Knowledge | None = None) -> dict[tuple[int, str], list[str]]:
    """For each step role no device of the cell can play: the catalogue devices (built-in and library) that could."""
    k = _k(knowledge)
    out: dict[tuple[int, str], list[str]] = {}
    for p in result.problems:
        if p.kind != "no_device" or p.role is None:
            continue
        needed = k.process(p.command).role(p.role).required_skill
        out[(p.step, p.role)] = [d.id for d in k.devices if any(k.taxonomy.is_a(s, needed) for s in d.skills)]
    return out


MORE_REPAIRS = 3
"""How many times :func:`assessed_repairs` asks the solver (for ``top``, then ``2 top``, ... repairs) while the
check refuses some of them."""


def assessed_repairs(
    task_or_path: TaskArg,
    cell_or_path: CellArg,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    top: int = 3,
    knowledge: Knowledge | None = None,
    checked: reasoning.CheckResult | None = None,
) -> list[reasoning.AssessedRepair]:
    """The repairs of :func:`repair` that checking them again confirms, with their side effects, ranked by their
    worst side effect, then by cost (:func:`plugnproduce.reasoning.repairs.sideeffects.ranking`). When the check refuses
    some of the solver's repairs, the solver is asked for more, up to :data:`MORE_REPAIRS` rounds. ``checked``: the
    task's :func:`check` in that cell, when the caller has it (it is not checked again)."""
    from plugnproduce import collector

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    the_task = as_task(task_or_path)
    devices = None if catalogue_or_folder is None else _devices(catalogue_or_folder, k)
    asked = top
    with collector.paused():  # repairs of a long task make long-lived results, not cyclic garbage
        for _ in range(MORE_REPAIRS):
            repairs = repair(the_task, the_cell, devices, asked, knowledge=k)
            assessed = reasoning.assess(repairs, the_task, the_cell, k, devices or (), checked)
            if len(assessed) >= top or len(repairs) < asked:
                break
            asked += top
    return assessed[:top]
