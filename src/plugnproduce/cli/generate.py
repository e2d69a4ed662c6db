"""``pnp generate``: a task's charts in W3C SCXML, written to a folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import typer

from plugnproduce.cli.app import JSON_OPTION, app, boundary, emit_json, knowledge
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import service
else:
    service = lazy_module("plugnproduce.service")

CELL_OPTION = typer.Option(..., "--cell", metavar="CELL", help="The cell file (YAML).")


def refuse(exc: service.ImplausibleTask, consequence: str, json_out: bool) -> NoReturn:
    """Say why an implausible task is refused (the reasoner's problems) and exit 1."""
    if json_out:
        emit_json(exc.result.to_json())
    else:
        typer.echo(f"task {exc.result.task} is not plausible in cell {exc.result.cell}; {consequence}", err=True)
        for p in exc.result.problems:
            typer.echo(str(p), err=True)
    raise typer.Exit(1) from None


@app.command()
@boundary
def generate(
    task: Path = typer.Argument(..., metavar="TASK", help="The task file (YAML)."),
    cell: Path = CELL_OPTION,
    out: Path = typer.Option(..., "--output", "-o", metavar="DIR",
                             help="Folder to write the charts to (created if missing)."),
    per_device: bool = typer.Option(False, "--per-device", help="Also write each device's program."),
    json_out: bool = JSON_OPTION,
) -> None:
    """Check a task, then write its specific process charts, task chart and closed-world chart.

    Exit 0 written, 1 the task is implausible (nothing is written), 2 bad input.
    """
    try:
        generated = service.generate(task, cell, per_device, knowledge(cell))
    except service.ImplausibleTask as exc:
        refuse(exc, "nothing written", json_out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for chart in generated.charts:
        path = out / chart.name
        path.write_bytes(chart.data)
        written.append({"file": str(path), "kind": chart.kind})
    if json_out:
        emit_json({"task": generated.task.task.name, "written": written})
        return
    for w in written:
        typer.echo(f"wrote {w['file']} ({w['kind']})")
