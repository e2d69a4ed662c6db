"""Use cases the HMI needs that :mod:`plugnproduce.service` does not offer yet.

Each function here composes service calls and a concept the way the service will; when
the service grows the use case (``service.generate``), the HMI calls it instead and this
module goes away. Nothing here decides anything the concepts do not.
"""

from __future__ import annotations

from dataclasses import dataclass

from plugnproduce import reasoning, service
from plugnproduce.codegen import GeneratedTask, generate_task
from plugnproduce.codegen.outputs import GeneratedChart, all_charts
from plugnproduce.description.model import Cell, Task
from plugnproduce.knowledge import Knowledge


@dataclass(frozen=True)
class Generation:
    """The plausibility of a task and, when plausible, the code generated for it."""

    check: reasoning.CheckResult
    generated: GeneratedTask | None
    charts: tuple[GeneratedChart, ...]


def generate(task: Task, cell: Cell, per_device: bool = False, knowledge: Knowledge | None = None) -> Generation:
    """Check a task and generate its charts with the bindings the check found (none when implausible)."""
    k = knowledge or service.knowledge()
    result = service.check(task, cell, k)
    if not result.plausible:
        return Generation(result, None, ())
    generated = generate_task(task, cell, result.bindings(), {p.id: p for p in k.processes}, k.taxonomy)
    return Generation(result, generated, tuple(all_charts(generated, cell, per_device)))
