"""Tasks between JSON and YAML: validation through the task file's checks, import and export.

``pnp validate`` checks task *files* (schema, SHACL shapes, structure). So that a task
from the editor gets exactly the same findings with the same messages, it is written to
a temporary YAML file, one line per parameter, validated there, and every problem is
mapped back from its line to the editor's field (``steps[1].params.grip_force``).
"""

from __future__ import annotations

import re
import tempfile
import threading
from pathlib import Path
from typing import Any

import yaml

from plugnproduce import service
from plugnproduce.description.loader import load_task, task_to_yaml
from plugnproduce.description.model import Task
from plugnproduce.errors import DescriptionError
from plugnproduce.hmi.schemas import TaskIn
from plugnproduce.knowledge import Knowledge
from plugnproduce.safeio import MAX_BYTES, PlainDumper

_validating = threading.Lock()
"""One validation at a time: the shapes engine is not meant to share its graphs between threads."""


def _block_yaml(task: TaskIn) -> str:
    steps = []
    for s in task.steps:
        entry: dict[str, Any] = {"command": s.command}
        if s.bind:
            entry["bind"] = dict(s.bind)
        if s.params:
            entry["params"] = dict(s.params)
        steps.append(entry)
    doc: dict[str, Any] = {"task": task.name}
    if task.description:
        doc["description"] = task.description
    if task.repeat != 1:
        doc["repeat"] = task.repeat
    doc["steps"] = steps
    return yaml.dump(doc, Dumper=PlainDumper, sort_keys=False, default_flow_style=False, allow_unicode=True)


def _fields(loaded: Task, rounds: int) -> dict[int, tuple[int, str]]:
    """Line in the written file → (editor row, field name)."""
    n = len(loaded.steps) // max(rounds, 1)
    out: dict[int, tuple[int, str]] = {}
    for row, step in enumerate(loaded.steps[:n]):
        if step.line is not None:
            out[step.line] = (row, f"steps[{row}]")
        for name, line in step.param_lines.items():
            out[line] = (row, f"steps[{row}].params.{name}")
    return out


def validate_task(task: TaskIn, knowledge: Knowledge | None = None) -> dict[str, Any]:
    """Validate a task as ``pnp validate`` validates a task file; each problem names its editor field."""
    with tempfile.TemporaryDirectory(prefix="pnp-hmi-") as folder:
        path = Path(folder) / "task.yaml"
        path.write_text(_block_yaml(task), encoding="utf-8")
        fields = _fields(load_task(path), task.repeat)
        with _validating:
            report = service.validate([path], knowledge)
        problems = []
        for p in report.sorted():
            row, field = fields.get(p.line, (None, "task")) if p.file == str(path) else (None, p.file)
            problems.append({"step": None if row is None else row + 1, "row": row, "field": field,
                             "message": p.message, "text": f"{field}: {p.message}"})
    return {"valid": report.valid, "problems": problems}


def import_yaml(data: bytes, filename: str = "task.yaml") -> Task:
    """Read a task description from YAML text with the task file's hardened reader.

    Errors name ``filename`` and the line, like ``pnp`` does for a file.
    """
    if len(data) > MAX_BYTES:
        raise DescriptionError(f"file is {len(data)} bytes; at most {MAX_BYTES} are accepted", filename)
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(filename).name).lstrip(".") or "task.yaml"
    with tempfile.TemporaryDirectory(prefix="pnp-hmi-") as folder:
        path = Path(folder) / name
        path.write_bytes(data)
        try:
            return load_task(path)
        except DescriptionError as exc:
            raise type(exc)(exc.message, name, exc.line) from exc


def export_yaml(task: Task) -> str:
    """The task description as YAML, as the task file format writes it."""
    return task_to_yaml(task)
