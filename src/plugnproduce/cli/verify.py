"""``pnp verify``: every interleaving of a task's program with the cell's device charts explored."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import JSON_OPTION, app, boundary, emit_json, fail, knowledge
from plugnproduce.cli.generate import CELL_OPTION, refuse
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import service
    from plugnproduce.service import Budget, Verification
else:
    service = lazy_module("plugnproduce.service")

INCONCLUSIVE_EXIT = 3
"""Exit code when the budget ran out before every interleaving was explored."""
MAX_STATES_OPTION = typer.Option(250_000, "--max-states", metavar="N", min=1,
                                 help="Most configurations to explore before answering 'inconclusive'.")
TIMEOUT_OPTION = typer.Option(60.0, "--timeout", metavar="SECONDS",
                              help="Most seconds to explore before answering 'inconclusive'.")


def budget(max_states: int, timeout: float) -> Budget:
    """The search budget of the options (a timeout that is not a positive number is bad input)."""
    from plugnproduce.service import Budget

    if not math.isfinite(timeout) or timeout <= 0:
        fail(f"error: --timeout {timeout}: expected a positive number of seconds")
    return Budget(max_states, timeout)


def exit_code(result: Verification) -> int:
    """0 proved, 1 refuted, 3 inconclusive."""
    return {"proved": 0, "refuted": 1}.get(result.verdict, INCONCLUSIVE_EXIT)


@app.command()
@boundary
def verify(
    task: Path = typer.Argument(..., metavar="TASK", help="The task file (YAML)."),
    cell: Path = CELL_OPTION,
    max_states: int = MAX_STATES_OPTION,
    timeout: float = TIMEOUT_OPTION,
    json_out: bool = JSON_OPTION,
) -> None:
    """Prove that every run of a task's program reaches done: every interleaving of the task chart with
    the cell's device charts (device delays unknown), no deadlock, no request a device refuses, no
    missing argument. A failure is shown as the shortest trace, each step at its description's file:line.

    Exit 0 proved, 1 refuted (or the task is implausible), 2 bad input, 3 inconclusive (budget ran out).
    """
    limits = budget(max_states, timeout)
    try:
        result = service.verify(task, cell, limits, knowledge(cell))
    except service.ImplausibleTask as exc:
        refuse(exc, "nothing to verify", json_out)
    if json_out:
        emit_json(result.to_json())
    else:
        for line in result.lines():
            typer.echo(line)
    raise typer.Exit(exit_code(result))
