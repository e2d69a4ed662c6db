"""Fixtures for code generation: the bin-picking cell, its processes and bound tasks."""

from __future__ import annotations

import pytest

from plugnproduce import service
from plugnproduce.codegen import GeneratedTask, generate_task
from plugnproduce.description.model import Cell, ProcessDescription, Task


def bind_by_skill(task: Task, cell: Cell, processes: dict[str, ProcessDescription]) -> list[dict[str, str]]:
    """Role bindings for tests: the task's own, else the one device of the cell with the role's skill."""
    out = []
    for step in task.steps:
        binding = {}
        for role in processes[step.command].roles:
            fit = [d.id for d in cell.devices if role.required_skill in d.skills]
            binding[role.name] = step.bind.get(role.name) or fit[0]
        out.append(binding)
    return out


@pytest.fixture(scope="session")
def processes() -> dict[str, ProcessDescription]:
    return {p.id: p for p in service.knowledge().processes}


@pytest.fixture(scope="session")
def bin_picking_cell() -> Cell:
    return service.cell(service.builtin("cells", "bin-picking.yaml"))


def generate(task_name: str, cell: Cell, processes: dict[str, ProcessDescription]) -> GeneratedTask:
    task = service.task(service.builtin("tasks", f"{task_name}.yaml"))
    return generate_task(task, cell, bind_by_skill(task, cell, processes), processes, service.knowledge().taxonomy)
