"""The request bodies of the HTTP API, and the task as JSON.

A task travels as ``{"name", "description", "repeat", "steps": [{"command", "bind", "params"}]}``,
the YAML task description's fields in JSON (``task`` is accepted for ``name``). It becomes
the model's :class:`~plugnproduce.description.model.Task` with :meth:`TaskIn.to_task`.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import AfterValidator, AliasChoices, BaseModel, ConfigDict, Field, WithJsonSchema, model_validator

from plugnproduce.description.model import Step, Task
from plugnproduce.safeio import MAX_DIGITS

TASK_SOURCE = "task"
"""The ``file`` of a task that came as JSON: problems name its steps, not a file."""

POSE_HELP = "a pose [x, y, z, rx, ry, rz] (metres, degrees)"


def _number(value: Any) -> bool:
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{value} is not a number a device can be given; expected a finite number")
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**MAX_DIGITS:
        raise ValueError(f"an integer of more than {MAX_DIGITS} digits")
    return isinstance(value, int | float) and not isinstance(value, bool)


def _param_value(value: Any) -> Any:
    if isinstance(value, str | bool) or _number(value):
        return value
    if isinstance(value, list) and len(value) <= 16 and all(_number(v) for v in value):
        return value
    kind = "a mapping" if isinstance(value, dict) else ("null" if value is None else "a list of non-numbers")
    raise ValueError(f"a parameter value is a number, text, true or false, or {POSE_HELP}; found {kind}")


ParamValue = Annotated[
    Any,
    AfterValidator(_param_value),
    WithJsonSchema({"anyOf": [{"type": "number"}, {"type": "string"}, {"type": "boolean"},
                              {"type": "array", "items": {"type": "number"}, "maxItems": 16}]}),
]


class StepIn(BaseModel):
    """One process command of a task."""

    model_config = ConfigDict(extra="forbid")

    command: str = Field(min_length=1, max_length=200, description="A process command, e.g. 'pick'.")
    bind: dict[str, Annotated[str, Field(min_length=1, max_length=200)]] = Field(
        default_factory=dict, description="Role name → device id (optional where only one device fits).")
    params: dict[str, ParamValue] = Field(
        default_factory=dict, description="Parameter name → value; a parameter left out takes its default.")


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
    steps: list[StepIn] = Field(min_length=1, max_length=1000)

    @model_validator(mode="after")
    def _not_too_long(self) -> TaskIn:
        if len(self.steps) * self.repeat > Task.MAX_STEPS:
            raise ValueError(f"{len(self.steps)} steps repeated {self.repeat} times make "
                             f"{len(self.steps) * self.repeat}; at most {Task.MAX_STEPS} are accepted")
        return self

    def to_task(self) -> Task:
        """The model's task: steps numbered from 1 in the expanded (repeated) order."""
        one_round = [Step(i + 1, s.command, dict(s.bind), dict(s.params)) for i, s in enumerate(self.steps)]
        return Task.repeated(self.name, one_round, TASK_SOURCE, self.description, self.repeat)


class PlugIn(BaseModel):
    """A catalogue device to plug into the cell."""

    model_config = ConfigDict(extra="forbid")

    device: str = Field(min_length=1, max_length=200, description="The id of a catalogue device.")


class RunIn(BaseModel):
    """A task to run in the current cell."""

    model_config = ConfigDict(extra="forbid")

    task: TaskIn
