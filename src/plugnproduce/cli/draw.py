"""``pnp draw``."""

from __future__ import annotations

from pathlib import Path

import typer

from plugnproduce.cli.application import app, boundary


@app.command()
@boundary
def draw(
    chart: Path = typer.Argument(..., metavar="CHART", help="An SCXML chart: device, process, task or closed-world."),
    output: Path = typer.Option(..., "-o", "--output", metavar="FILE",
                                help="Picture to write: .svg, .png, .pdf or .dot."),
    step: int | None = typer.Option(None, "--step", metavar="N", min=1,
                                    help="Of a task or closed-world chart, the step to draw with its regions."),
) -> None:
    """Draw a state chart: regions as clusters, commands on the edges; a task's steps in order,
    each one box with its process and binding.

    Exit 0 drawn, 2 bad input (an unreadable chart, an unknown picture format).
    """
    from plugnproduce.service.drawings import draw

    typer.echo(f"wrote {draw(chart, output, step)}")
