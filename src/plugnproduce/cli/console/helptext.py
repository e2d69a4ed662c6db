"""Help as a user reads it: arguments named in capitals as they are typed (``TASK``, ``PATH...``,
``[RUN]``), never a Python type (``<path>``, ``<list[Path]>``) nor typer's ``{TASK}``."""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any, TypeVar

import typer
from typer import _click as click  # typer vendors its own click: its commands take these types
from typer.core import TyperCommand, TyperGroup

from plugnproduce.cli.console.coercion import plain_values


def is_argument(param: click.Parameter) -> bool:
    """A positional argument (typer's own parameter classes are not :class:`click.Argument`)."""
    return param.param_type_name == "argument"


def argument_name(param: click.Parameter) -> str:
    """The argument as a user types it: its metavar (or name) in capitals, ``...`` when it repeats."""
    name = (param.metavar or param.name or "value").upper()
    return name if param.nargs == 1 or name.endswith("...") else f"{name}..."


F = TypeVar("F", bound=Callable[..., Any])


class PlainCommand(TyperCommand):
    """A command whose usage line and help name its arguments plainly, and whose texts and paths are taken
    without pydantic (:mod:`plugnproduce.cli.console.coercion`)."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        """As typer parses them, texts and paths turned plainly."""
        plain_values(self.get_params(ctx))
        return super().parse_args(ctx, args)

    def collect_usage_pieces(self, ctx: click.Context) -> list[str]:
        """``[OPTIONS] TASK``, an optional argument in brackets: ``[OPTIONS] [RUN]``."""
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if is_argument(param):
                name = argument_name(param)
                pieces.append(name if param.required else f"[{name}]")
            else:
                pieces.extend(param.get_usage_pieces(ctx))
        return pieces

    def format_options(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The arguments (by their plain names, with their help), then the options."""
        args: list[tuple[str, str]] = []
        opts: list[tuple[str, str]] = []
        for param in self.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is None:
                continue
            if is_argument(param):
                args.append((argument_name(param), record[1]))
            else:  # an option without a metavar: its name in capitals, not its Python type
                opts.append((re.sub(r" <[^>]*>", f" {(param.name or 'value').upper()}", record[0]), record[1]))
        for title, rows in (("Arguments", args), ("Options", opts)):
            if rows:
                with formatter.section(title):
                    formatter.write_dl(rows)


class PlainGroup(TyperGroup):
    """The command group, whose own options' texts and paths are taken without pydantic."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        """As typer parses them, texts and paths turned plainly."""
        plain_values(self.get_params(ctx))
        return super().parse_args(ctx, args)


class PlainTyper(typer.Typer):
    """A typer application whose commands are :class:`PlainCommand` (and group :class:`PlainGroup`) unless told
    otherwise."""

    def __init__(self, *args: Any, cls: type[TyperGroup] | None = None, **kwargs: Any) -> None:
        super().__init__(*args, cls=cls or PlainGroup, **kwargs)

    def command(self, *args: Any, cls: type[TyperCommand] | None = None, **kwargs: Any) -> Callable[[F], F]:
        """As :meth:`typer.Typer.command`, with plain help."""
        return super().command(*args, cls=cls or PlainCommand, **kwargs)
