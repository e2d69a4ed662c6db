"""The request bodies of the HTTP API, and the task as JSON.

A task travels as ``{"name", "description", "repeat", "steps": [...]}``, the YAML task
description's fields in JSON (``task`` is accepted for ``name``): each item of ``steps`` is a
step ``{"name", "command", "bind", "params", "on"}`` (a parameter may be a data link
``{"from": STEP, "output": NAME}``; ``on`` maps an outcome to the steps of its branch) or a loop
``{"loop": {"until", "while", "max", "steps"}}``. It becomes
the model's :class:`~plugnproduce.description.model.Task` with :meth:`TaskIn.to_task`, read by the
task file's reader, so that a task from the editor means what the same task file means.
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Annotated, Any

from pydantic import (
    AfterValidator,
    AliasChoices,
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    PrivateAttr,
    Tag,
    WithJsonSchema,
    model_validator,
)

from plugnproduce import service
from plugnproduce.errors import DescriptionError
from plugnproduce.service import MAX_DIGITS, Task

TASK_SOURCE = "task"
"""The ``file`` of a task that came as JSON: problems name its steps, not a file."""

POSE_HELP = "a pose [x, y, z, rx, ry, rz] (metres, degrees)"


def _number(value: Any) -> bool:
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{value} is not a number a device can be given; expected a finite number")
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**MAX_DIGITS:
        raise ValueError(f"an integer of more than {MAX_DIGITS} digits")
    return isinstance(value, int | float) and not isinstance(value, bool)


LINK_HELP = "an earlier step's output {from: STEP, output: NAME} (with offset: [x, y, z, rx, ry, rz] for a pose)"
NAME_SCHEMA = {"type": "string", "maxLength": 200}


def _link(value: dict[Any, Any]) -> bool:
    """A link's form (the task reader judges its offset's numbers)."""
    offset = value.get("offset")
    return {"from", "output"} <= set(value) <= {"from", "output", "offset"} and \
        all(isinstance(value[k], str) and 0 < len(value[k]) <= 200 for k in ("from", "output")) and \
        (offset is None or (isinstance(offset, list) and len(offset) <= 16))


def _param_value(value: Any) -> Any:
    if isinstance(value, str | bool) or _number(value):
        return value
    if isinstance(value, list) and len(value) <= 16 and all(_number(v) for v in value):
        return value
    if isinstance(value, dict) and _link(value):
        return value
    kind = "another mapping" if isinstance(value, dict) else ("null" if value is None else "a list of non-numbers")
    raise ValueError(f"a parameter value is a number, text, true or false, {POSE_HELP} or {LINK_HELP}; found {kind}")


ParamValue = Annotated[
    Any,
    AfterValidator(_param_value),
    WithJsonSchema({"anyOf": [{"type": "number"}, {"type": "string"}, {"type": "boolean"},
                              {"type": "array", "items": {"type": "number"}, "maxItems": 16},
                              {"type": "object", "properties": {"from": NAME_SCHEMA, "output": NAME_SCHEMA,
                                                                "offset": {"type": "array", "items": {"type": "number"},
                                                                           "minItems": 6, "maxItems": 6}},
                               "required": ["from", "output"], "additionalProperties": False}]}),
]


class StepIn(BaseModel):
    """One process command of a task."""

    model_config = ConfigDict(extra="forbid")

    name: str | None = Field(None, min_length=1, max_length=200,
                             description="The step's name, by which later steps take its outputs.")
    command: str = Field(min_length=1, max_length=200, description="A process command, e.g. 'pick'.")
    bind: dict[str, Annotated[str, Field(min_length=1, max_length=200)]] = Field(
        default_factory=dict, description="Role name → device id (optional where only one device fits).")
    params: dict[str, ParamValue] = Field(
        default_factory=dict, description="Parameter name → value; a parameter left out takes its default.")
    on: dict[Annotated[str, Field(min_length=1, max_length=200)],
             Annotated[list[StepIn], Field(min_length=1, max_length=1000)]] | None = Field(
        None, description="Branches: outcome → the steps that run only when this step ends with that outcome.")


class LoopBodyIn(BaseModel):
    """A loop: its steps run again and again until one of them ends with ``until`` (while the last outcome they
    reported is ``while``), at most ``max`` times."""

    model_config = ConfigDict(extra="forbid")

    until: str | None = Field(None, min_length=1, max_length=200, description="An outcome, e.g. 'BinEmpty'.")
    while_: str | None = Field(None, alias="while", min_length=1, max_length=200,
                               description="An outcome the loop goes on while its steps report it, e.g. 'PartFound'.")
    max: int | None = Field(None, ge=1, le=1_000_000, description="The most iterations.")
    steps: list[StepIn] = Field(min_length=1, max_length=1000)


class LoopIn(BaseModel):
    """A ``loop`` item of a task's steps."""

    model_config = ConfigDict(extra="forbid")

    loop: LoopBodyIn


STEP_TAG, LOOP_TAG = "step item", "loop item"
"""How validation errors would name a step or a loop item of ``steps``: left out of field names."""


def _item_kind(item: Any) -> str:
    return LOOP_TAG if isinstance(item, dict | LoopIn) and (not isinstance(item, dict) or "loop" in item) else STEP_TAG


TaskItem = Annotated[Annotated[StepIn, Tag(STEP_TAG)] | Annotated[LoopIn, Tag(LOOP_TAG)], Discriminator(_item_kind)]
"""An item of a task's steps: a step, or a loop (an item with ``loop``)."""


class TaskIn(BaseModel):
    """A task description as JSON."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={"examples": [{
            "name": "bin-picking", "repeat": 1,
            "steps": [{"command": "bin-pick", "params": {"grip_force": 45}}, {"command": "place"}],
        }]},
    )

    name: str = Field(min_length=1, max_length=200, validation_alias=AliasChoices("name", "task"))
    description: str = Field("", max_length=2000)
    repeat: int = Field(1, ge=1, le=1000, description="The steps run this many times in a row.")
    steps: list[TaskItem] = Field(min_length=1, max_length=1000)
    _task: Task | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _not_too_long(self) -> TaskIn:
        if len(self.steps) * self.repeat > Task.MAX_STEPS:
            raise ValueError(f"{len(self.steps)} steps repeated {self.repeat} times make "
                             f"{len(self.steps) * self.repeat}; at most {Task.MAX_STEPS} are accepted")
        return self

    @model_validator(mode="after")
    def _readable(self) -> TaskIn:
        """Read the task as the task file reader reads it: a duplicate step name or a loop in a
        repeated task is refused here, with the reader's message."""
        doc = {"task": self.name, "description": self.description, "repeat": self.repeat,
               "steps": [s.model_dump(exclude_none=True, by_alias=True) for s in self.steps]}
        try:
            task = service.task_from_text(json.dumps(doc, ensure_ascii=False), TASK_SOURCE)
        except DescriptionError as exc:
            raise ValueError(exc.message) from exc
        # the JSON's lines are no file's lines: problems name the steps instead
        steps = tuple(dataclasses.replace(s, line=None, param_lines={}) for s in task.steps)
        loops = tuple(dataclasses.replace(lp, line=None) for lp in task.loops)
        branches = tuple(dataclasses.replace(b, line=None) for b in task.branches)
        self._task = dataclasses.replace(task, steps=steps, loops=loops, branches=branches)
        return self

    def to_task(self) -> Task:
        """The model's task: steps numbered from 1 in the expanded (repeated, looped) order."""
        if self._task is None:
            raise TypeError("a TaskIn is read when it is validated")
        return self._task


class PlugIn(BaseModel):
    """A catalogue device to plug into the cell."""

    model_config = ConfigDict(extra="forbid")

    device: str = Field(min_length=1, max_length=200, description="The id of a catalogue device.")


class RunIn(BaseModel):
    """A task to run in the current cell."""

    model_config = ConfigDict(extra="forbid")

    task: TaskIn


class ResumeIn(BaseModel):
    """The plan the operator confirmed: the devices' states it was planned from (none: plan and go on)."""

    model_config = ConfigDict(extra="forbid")

    states: dict[str, str] | None = None
