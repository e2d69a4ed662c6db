"""``pnp generate``: a task's charts in W3C SCXML, written to a folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import typer

from plugnproduce.cli.application import JSON_OPTION, app, boundary, emit_json, knowledge
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
        for p in exc.result.problems:  # in the words of pnp check
            typer.echo(f"{p.where}: {p.reason.plain}", err=True)
    raise typer.Exit(1) from None


@app.command()
@boundary
def generate(
    task: Path = typer.Argument(..., metavar="TASK", help="The task file (YAML)."),
    cell: Path = CELL_OPTION,
    out: Path = typer.Option(..., "--output", "-o", metavar="DIR",
                             help="Folder to write the charts to (created if missing)."),
    per_device: bool = typer.Option(False, "--per-device", help="Also write each device's program."),
    no_verify: bool = typer.Option(False, "--no-verify", help="Write the charts without verifying them first."),
    max_states: int = typer.Option(250_000, "--max-states", metavar="N", min=1,
                                   help="Verification: most configurations to explore."),
    timeout: float = typer.Option(60.0, "--timeout", metavar="SECONDS", help="Verification: most seconds to spend."),
    json_out: bool = JSON_OPTION,
) -> None:
    """Check a task, verify its program over every interleaving (as pnp verify), then write its specific
    process charts, task chart and closed-world chart.

    Exit 0 written, 1 the task is implausible or its program refuted (nothing is written), 2 bad input,
    3 verification inconclusive within its budget (nothing is written; see --max-states, --timeout, --no-verify).
    """
    from plugnproduce.cli.verify import budget, exit_code
    limits = None if no_verify else budget(max_states, timeout)
    try:
        generated = service.generate(task, cell, per_device, knowledge(cell), verify=limits)
    except service.ImplausibleTask as exc:
        refuse(exc, "nothing written", json_out)
    except service.ImplausibleStep as exc:  # the check passed it, yet its code cannot be built: a finding, at its line
        typer.echo(f"{task}:{exc.step.line or 1}: {exc}; nothing written", err=True)
        raise typer.Exit(1) from None
    except service.Unverified as exc:
        if json_out:
            emit_json(exc.verification.to_json())
        else:
            typer.echo("\n".join(exc.verification.lines() + ["nothing written"]), err=True)
        raise typer.Exit(exit_code(exc.verification)) from None
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for chart in generated.charts:
        path = out / chart.name
        path.write_bytes(chart.data)
        written.append({"file": str(path), "kind": chart.kind})
    proof = generated.verification
    if json_out:
        emit_json({"task": generated.task.task.name, "written": written,
                   "verification": proof.to_json() if proof is not None else None})
        return
    if proof is not None:
        typer.echo(proof.lines()[0])
    for w in written:
        typer.echo(f"wrote {w['file']} ({w['kind']})")
