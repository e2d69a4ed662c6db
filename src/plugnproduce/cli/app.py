"""The typer application, its error boundary and output helpers shared by all commands."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from functools import wraps
from typing import Any, NoReturn, TypeVar

import typer

from plugnproduce.errors import DescriptionError, PlugNProduceError

app = typer.Typer(
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain help: rich's formatter alone costs more than the rest of start-up
    help="Plug'n'Produce cell controller: from device and process descriptions to executable SCXML.",
)

F = TypeVar("F", bound=Callable[..., Any])

JSON_OPTION = typer.Option(False, "--json", help="Machine-readable output.")


def fail(message: str, code: int = 2) -> NoReturn:
    """Print one line to stderr and exit (2: bad input)."""
    typer.echo(message, err=True)
    raise typer.Exit(code)


def boundary(func: F) -> F:
    """Turn the project's errors into one line and exit code 2, never a traceback."""

    @wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except DescriptionError as exc:
            fail(exc.location_message())
        except KeyError as exc:
            fail(f"error: unknown {exc.args[0] if exc.args else 'name'}")
        except PlugNProduceError as exc:
            fail(f"error: {exc}")
        except OSError as exc:
            fail(f"{getattr(exc, 'filename', None) or 'error'}: {exc.strerror or exc}")

    return wrapper  # type: ignore[return-value]


def emit_json(data: object) -> None:
    """Write a JSON document to stdout."""
    json.dump(data, sys.stdout, indent=2, sort_keys=False, default=str)
    sys.stdout.write("\n")


def main() -> None:
    """Entry point of the ``pnp`` console script."""
    app()
