"""Command-line values turned into their Python types without pydantic where nothing needs it.

typer turns every value of a command's parameters into its annotated type with a pydantic
``TypeAdapter``, even a file name into a ``Path``: importing pydantic and building the adapters
costs several times a bare interpreter's start, in every command. Texts, paths (with typer's own
checks of existence and kind) and lists of them are turned here as typer would turn them; so are the
numbers a command declares as defaults, within their bounds. Any other value (a number the user
typed, a choice) is left to typer, whose adapter is built only then.
"""

from __future__ import annotations

import os
from functools import cached_property
from pathlib import Path
from typing import Any, get_args, get_origin

from typer import _click as click  # typer vendors its own click: its commands take these types
from typer._coercion import RuntimeParam, build_runtime_param, resolve_type_descriptor
from typer._param_types import coerce_cli_path, routes_to_path
from typer.core import _TyperParameter
from typer.models import ParameterInfo


def _plain_leaf(annotation: Any, info: ParameterInfo) -> bool:
    """A single value turned without pydantic: a text, a path, or a flag."""
    if info.parser is not None:
        return False
    return annotation in (str, bool) or (isinstance(annotation, type) and issubclass(annotation, Path)
                                 and routes_to_path(annotation, info))


def is_plain(annotation: Any, info: ParameterInfo) -> bool:
    """The parameter's values are texts, paths or flags, or a list of them."""
    if get_origin(annotation) is list:
        (item,) = get_args(annotation)
        return _plain_leaf(item, info)
    return _plain_leaf(annotation, info)


def _a_number_in_bounds(annotation: Any, info: ParameterInfo, value: Any) -> bool:
    """``value`` is already a number of the annotated kind (an int for a float too) within the bounds."""
    if info.parser is not None or annotation not in (int, float) or isinstance(value, bool):
        return False
    if not isinstance(value, int) and not (annotation is float and isinstance(value, float)):
        return False
    return (info.min is None or value >= info.min) and (info.max is None or value <= info.max)


class PlainRuntimeParam(RuntimeParam):
    """A text, a path or a flag (or a list of them), turned as typer's adapter turns it."""

    def _coerce_value(self, value: Any, param: _TyperParameter, ctx: click.Context) -> Any:
        if _a_number_in_bounds(self.annotation, self.parameter_info, value):
            return self.annotation(value)  # a default the command declares, not a text the user typed
        if not is_plain(self.annotation, self.parameter_info):
            return self._typer_own()._coerce_value(value, param, ctx)
        annotation: Any = self.annotation
        if get_origin(annotation) is list:
            (item,) = get_args(annotation)
            values = value if isinstance(value, (list, tuple)) else [value]
            return [self._leaf(item, v, param, ctx) for v in values]
        return self._leaf(annotation, value, param, ctx)

    def _leaf(self, annotation: Any, value: Any, param: _TyperParameter, ctx: click.Context) -> Any:
        if annotation is str:
            return os.fsdecode(value) if isinstance(value, bytes) else str(value)
        if annotation is bool:
            if isinstance(value, bool):
                return value
            return self._typer_own()._coerce_value(value, param, ctx)  # "yes", "0", ...: as typer reads them
        path_type: Any = self.parameter_info.path_type or annotation
        if not isinstance(value, path_type):
            value = path_type(os.fsdecode(value) if isinstance(value, bytes) else str(value))
        return coerce_cli_path(value, self.parameter_info, path_type=path_type, param=param, ctx=ctx)


    @cached_property
    def _typer_own_param(self) -> RuntimeParam:
        return build_runtime_param(resolve_type_descriptor(self.annotation, self.parameter_info))

    def _typer_own(self) -> RuntimeParam:
        """typer's own turning of this parameter (with a pydantic adapter), built when first needed."""
        return self._typer_own_param


def plain_values(params: list[click.Parameter]) -> None:
    """Give the parameters a turning that needs no pydantic for texts, paths and flags, and builds typer's own
    (with pydantic) only when a value of another kind is given."""
    for param in params:
        if not isinstance(param, _TyperParameter) or param._runtime_param is not None:
            continue
        descriptor = param.type_descriptor
        if descriptor.file_annotation is None:
            param._runtime_param = PlainRuntimeParam(annotation=descriptor.annotation,
                                                     parameter_info=descriptor.parameter_info)
