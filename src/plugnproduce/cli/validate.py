"""``pnp validate``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import JSON_OPTION, app, boundary, emit_json, knowledge
from plugnproduce.cli.console.progress import Phases, on_a_terminal
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import service
else:
    service = lazy_module("plugnproduce.service")


@app.command()
@boundary
def validate(
    paths: list[Path] = typer.Argument(..., metavar="PATH...", help="Description files or folders."),
    json_out: bool = JSON_OPTION,
) -> None:
    """Check descriptions: hardened parsing, W3C SCXML schema, SHACL shapes, structure.

    Exit 0 valid, 1 invalid, 2 unreadable or hostile input.
    """
    with Phases(on_a_terminal(json_out)) as phases:
        report = service.validate(list(paths), knowledge(), progress=phases)
        phases.close(last_done=True)
    problems = report.sorted()
    if json_out:
        emit_json({"valid": report.valid, "files": len(report.files), "problems": [p.to_json() for p in problems]})
    else:
        for p in problems:
            typer.echo(str(p))
        if report.valid:
            typer.echo(f"{len(report.files)} files valid")
    if report.unreadable:
        raise typer.Exit(2)
    if not report.valid:
        raise typer.Exit(1)
