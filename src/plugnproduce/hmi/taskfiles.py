"""Tasks between JSON and YAML: validation through the task file's checks, import and export.

``pnp validate`` checks task *files* (schema, SHACL shapes, structure). So that a task
from the editor gets exactly the same findings with the same messages, it is written as
a task file, one line per value, read back with the task file's reader and validated;
every problem is mapped back from its line to the editor's field
(``steps[1].params.grip_force``). Nothing is written to disk.
"""

from __future__ import annotations

import re
import threading
from pathlib import Path
from typing import Any

from plugnproduce import service
from plugnproduce.hmi.schemas import TaskIn
from plugnproduce.hmi.views import editor_rows
from plugnproduce.service import Knowledge, Task, concept_value

_validating = threading.Lock()
"""One validation at a time: the shapes engine is not meant to share its graphs between threads."""

EDITOR_FILE = "task.yaml"
"""The name the editor's task goes by while it is validated as a task file."""


def _fields(loaded: Task) -> dict[int, tuple[int, str]]:
    """Line in the written file → (editor row, field name); a loop's line is its first step's row, a branch's
    line its step's row (editor rows count every step as written, a branch's steps after their step)."""
    out: dict[int, tuple[int, str]] = {}
    rows = editor_rows(loaded)
    for lp in loaded.loops:
        if lp.line is not None:
            out[lp.line] = (rows[lp.entry][0], f"steps[{rows[lp.entry][0]}].loop")
    for b in loaded.branches:
        if b.line is not None:
            out[b.line] = (rows[b.step][0], f"steps[{rows[b.step][0]}].on.{concept_value(b.outcome)}")
    for step in loaded.one_round():
        row, first = rows[step.index]
        if first != 1:
            continue
        if step.line is not None:
            out[step.line] = (row, f"steps[{row}]")
        for name, line in step.param_lines.items():
            out[line] = (row, f"steps[{row}].params.{name}")
    return out


def validate_task(task: TaskIn, knowledge: Knowledge | None = None) -> dict[str, Any]:
    """Validate a task as ``pnp validate`` validates a task file; each problem names its editor field."""
    loaded = service.task_from_text(service.task_text(task.to_task(), block=True), EDITOR_FILE)
    fields = _fields(loaded)
    with _validating:
        report = service.validate_tasks([loaded], knowledge)
    problems = []
    for p in report.sorted():
        row, field = fields.get(p.line, (None, "task")) if p.file == loaded.file else (None, p.file)
        problems.append({"step": None if row is None else row + 1, "row": row, "field": field,
                         "message": p.message, "text": f"{field}: {p.message}"})
    return {"valid": report.valid, "problems": problems}


def import_yaml(data: bytes, filename: str = "task.yaml") -> Task:
    """Read a task description from YAML text with the task file's hardened reader.

    Errors name ``filename`` and the line, like ``pnp`` does for a file.
    """
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(filename).name).lstrip(".") or "task.yaml"
    return service.task_from_text(data, name)


def export_yaml(task: Task) -> str:
    """The task description as YAML, as the task file format writes it."""
    return service.task_text(task)
