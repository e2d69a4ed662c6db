"""The ``pnp`` command line: a thin layer over :mod:`plugnproduce.service`."""

from __future__ import annotations

import typer

app = typer.Typer(no_args_is_help=True, add_completion=False, help="Plug'n'Produce cell controller.")


def main() -> None:
    """Entry point of the ``pnp`` console script."""
    app()
