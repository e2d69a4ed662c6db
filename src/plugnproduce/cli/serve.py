"""``pnp serve``: the Generic HMI (HTTP API and web page) in one process."""

from __future__ import annotations

import socket
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce import service
from plugnproduce.cli.app import app, boundary, fail

if TYPE_CHECKING:
    from plugnproduce.hmi import CellSource, Runner

LOOPBACK_NAMES = ("127.0.0.1", "localhost")


def journal_folder() -> Path:
    """Where runs leave their journals."""
    return Path.home() / ".cache" / "plugnproduce" / "runs"


def cell_source(cell: Path | None) -> CellSource:
    """The cell the HMI shows: a cell file (default: the built-in bin-picking cell), plugged from the catalogue.

    Hook for ``--sim`` and discovery: return a source over the simulated or live cell here
    (a :class:`~plugnproduce.hmi.CellSource` fed by :class:`~plugnproduce.discovery.LiveCell`).
    """
    from plugnproduce.hmi import FileCellSource

    return FileCellSource(service.cell(cell or service.builtin("cells", "bin-picking.yaml")), service.catalogue())


def runner_for(source: CellSource) -> Runner:
    """Who runs tasks: for now the device models (:class:`~plugnproduce.hmi.ModelRunner`).

    Hook for the executor: return a :class:`~plugnproduce.hmi.Runner` that drives the devices here.
    """
    from plugnproduce.hmi import ModelRunner

    return ModelRunner(lambda: source.cell, journal_folder())


def _listen(host: str, port: int) -> socket.socket:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    try:
        return socket.create_server((host, port), family=family)
    except OSError as exc:
        fail(f"--host {host} --port {port}: cannot listen: {exc.strerror or exc}")


@app.command()
@boundary
def serve(
    cell: Path | None = typer.Option(None, "--cell", help="The cell file (default: the built-in bin-picking cell)."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to listen on."),
    port: int = typer.Option(0, "--port", min=0, max=65535, help="Port to listen on (0: any free port)."),
    token_file: Path | None = typer.Option(None, "--token-file",
                                           help="Read the bearer token from this file (default: a new one)."),
) -> None:
    """Serve the Generic HMI: the live cell, offered commands, task editor, check/repair, runs.

    Prints the page's URL and the bearer token that requests changing the cell or a run need.
    """
    import uvicorn

    from plugnproduce.hmi import create_app
    from plugnproduce.hmi.security import new_token, read_token

    token = read_token(token_file) if token_file else new_token()
    source = cell_source(cell)
    service.knowledge()  # the taxonomy and processes, loaded once before the first request
    allowed = list(LOOPBACK_NAMES) if host in LOOPBACK_NAMES else None
    application = create_app(source, runner_for(source), token, allowed_hosts=allowed)
    sock = _listen(host, port)
    bound = sock.getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    url = f"http://{shown}:{bound}/"
    typer.echo(f"Plug'n'Produce HMI on {url}")
    if token_file:
        typer.echo(f"open {url} and give the token from {token_file}")
    else:
        typer.echo(f"open {url}#token={token}")
        typer.echo(f"token: {token}")
    config = uvicorn.Config(application, log_level="warning", timeout_graceful_shutdown=2, lifespan="on", ws="none")
    try:
        uvicorn.Server(config).run(sockets=[sock])  # Ctrl-C: a graceful shutdown, then KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    typer.echo("stopped")
