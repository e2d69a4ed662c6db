"""``pnp teach``: read a pose (or another value) a device reports, and hold it to the device's contracts."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import DISCOVERY_OPTION, JSON_OPTION, app, boundary, emit_json, knowledge
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import controller
else:
    controller = lazy_module("plugnproduce.controller")


@app.command()
@boundary
def teach(
    device: str = typer.Argument(..., metavar="DEVICE", help="The device of the cell that reports the value."),
    quantity: str = typer.Argument(..., metavar="QUANTITY", help="The quantity it reports (TargetPose)."),
    cell: Path = typer.Option(..., "--cell", metavar="CELL", help="The cell file."),
    discovery_timeout: float | None = DISCOVERY_OPTION,
    json_out: bool = JSON_OPTION,
) -> None:
    """Teach-in: find the device, read the value it reports now (the pose a robot was guided to) by its state
    query, print it, and hold it to every contract of the device's requests that take that quantity.

    Exit 0 read and within the contracts, 1 a contract refuses it (which and why), 2 bad input (an unknown
    device or quantity, a device not found).
    """
    import asyncio  # here, not at the top: the other commands need no event loop

    k = knowledge(cell)
    taught = asyncio.run(controller.teach(device, quantity, cell, k, discovery_timeout or controller.DISCOVERY_SECONDS))
    if json_out:
        emit_json(taught.to_json())
    else:
        typer.echo(taught.line())
        if taught.accepted:
            typer.echo("within " + ("; ".join(taught.held_to) if taught.held_to else
                                    f"every contract: no request of {taught.device} takes {taught.quantity}"))
    for why in taught.refused:
        typer.echo(f"refused: {why}", err=True)
    if not taught.accepted:
        raise typer.Exit(1)
