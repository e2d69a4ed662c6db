"""``pnp runs``: the past runs, newest first (``pnp report`` prints one of them)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import JSON_OPTION, app, boundary, emit_json
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import service
else:
    service = lazy_module("plugnproduce.service")  # `pnp --help` imports none of it

HEADER = ("ID", "TASK", "CELL", "START", "STATUS", "SPEED", "DURATION")


def _speed(factor: float | None) -> str:
    """A simulated run's speed factor (``-``: real devices)."""
    return "-" if factor is None else f"{factor:g}"


def _duration(seconds: float | None) -> str:
    if seconds is None:
        return "?"
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest:02d} s"


@app.command()
@boundary
def runs(json_out: bool = JSON_OPTION) -> None:
    """List the past runs (in PNP_RUNS), newest first: id, task, cell, start, status, speed and duration.

    A run without an end is shown as crashed (or it is still running). SPEED is the factor a run's simulated
    devices worked at (pnp run --sim --speed F); '-' for real devices. 'pnp report RUN' prints one.

    Exit 0 listed (none too), 2 an unreadable runs folder.
    """
    past = service.runs()
    if json_out:
        emit_json([r.to_json() for r in past])
        return
    if not past:
        typer.echo(f"no runs yet in {service.runs_folder()}", err=True)
        return
    rows = [HEADER] + [(r.id, r.task, r.cell, r.started_text(), r.status, _speed(r.speed), _duration(r.duration))
                       for r in past]
    widths = [max(len(row[i]) for row in rows) for i in range(len(HEADER) - 1)]
    for row in rows:
        typer.echo("  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=False)) + "  " + row[-1])
