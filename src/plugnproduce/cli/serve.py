"""``pnp serve``: the Generic HMI (HTTP API and web page) in one process."""

from __future__ import annotations

import os
import signal
import socket
import sys
import threading
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import INTERFACE_OPTION, app, boundary, fail, interface_address, knowledge
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    import asyncio

    import uvicorn
    from fastapi import FastAPI

    from plugnproduce import controller, service
    from plugnproduce.controller import CellSource, Runner
else:
    asyncio = lazy_module("asyncio")  # the event loop is started by the commands that use it
    controller = lazy_module("plugnproduce.controller")
    service = lazy_module("plugnproduce.service")

LOOPBACK_NAMES = ("127.0.0.1", "localhost")


def cell_source(cell: Path | None, sim: bool, faults: str = "", bin_parts: int | None = None,
                bin_seed: int = 0, discovery_timeout: float | None = None, interface: str | None = None,
                serve_lds: int | None = None) -> CellSource:
    """The cell the HMI shows, as discovery sees it.

    With ``sim`` the devices of ``cell`` (default: the built-in bin-picking cell) are simulated
    on a private loopback SSDP network and can be plugged and unplugged from the page, working on
    a simulated bin of ``bin_parts`` parts placed by ``bin_seed`` if given (else, for the runs of tasks that loop
    on a localized pose, a bin of :data:`~plugnproduce.controller.DEFAULT_BIN_PARTS` parts); without, the devices are
    the ones on the network (``PNP_SSDP_PORT``) and plug in themselves. Both are on ``interface`` (a name or an
    address; default ``PNP_INTERFACE``, else loopback). ``discovery_timeout`` bounds the
    wait for discovery to see the simulated devices start, plug or unplug (default
    ``controller.SIMULATED_DISCOVERY_SECONDS``), or, without ``sim``, the first search (default 1 s). Without
    ``sim``, ``serve_lds`` (a port, 0: any free one) runs a Local Discovery Server on the interface for the OPC UA
    devices to register with (its endpoint printed once it listens).
    """
    if not sim:
        name = service.cell(cell, knowledge()).name if cell else "live"
        return controller.LiveCellSource(controller.network_from_env(interface), name=name, knowledge=knowledge(cell),
                                         search_timeout=discovery_timeout or 1.0, serve_lds=serve_lds,
                                         announce=lambda lds: typer.echo(f"Local Discovery Server on {lds}"))
    cell = cell or service.builtin("cells", "bin-picking.yaml")
    k = knowledge(cell)
    parts = controller.SimulatedBin(bin_parts, bin_seed) if bin_parts is not None else None
    return controller.SimulatedCellSource(
        service.cell(cell, k), service.catalogue(knowledge=k), faults=faults, knowledge=k, bin=parts,
        default_bin=controller.SimulatedBin(controller.DEFAULT_BIN_PARTS, bin_seed),
        wait=discovery_timeout or controller.SIMULATED_DISCOVERY_SECONDS,
        interface=controller.chosen_address(interface))


def runner_for(source: CellSource, cell: Path | None = None) -> Runner:
    """Who runs tasks: the executor, on the devices of the source's cell, journalling into the runs folder."""
    return controller.ExecutorRunner(source, service.runs_folder(), knowledge(cell))


def _listen(host: str, port: int, option: str = "--port") -> socket.socket:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    try:
        return socket.create_server((host, port), family=family)
    except OSError as exc:
        where = f"--host {host} --port {port}" if option == "--port" else f"{option} {port} on {host}"
        fail(f"{where}: cannot listen: {exc.strerror or exc}")


@app.command()
@boundary
def serve(
    cell: Path | None = typer.Option(None, "--cell", metavar="CELL",
                                     help="With --sim: the cell to simulate (default: the built-in "
                                          "bin-picking cell); without: only its name is used."),
    sim: bool = typer.Option(False, "--sim", help="Simulate the cell's devices on a private SSDP network (on "
                             "loopback or --interface); "
                             "they can be plugged and unplugged from the page."),
    faults: str = typer.Option("", "--faults", metavar="SPEC", help="With --sim: faults to inject, as for pnp run."),
    bin_parts: int | None = typer.Option(None, "--bin-parts", metavar="N", min=0, max=10_000,
                                         help="With --sim: a simulated bin of N parts at random poses (as pnp run; "
                                              "default 5 for the runs of tasks that loop on a localized pose)."),
    bin_seed: int = typer.Option(0, "--bin-seed", metavar="S", help="With --bin-parts: the seed that places them."),
    host: str = typer.Option("127.0.0.1", "--host", metavar="ADDRESS", help="Address to listen on."),
    port: int = typer.Option(0, "--port", min=0, max=65535, metavar="PORT",
                             help="Port to listen on (0: any free port)."),
    token_file: Path | None = typer.Option(None, "--token-file", metavar="FILE",
                                           help="Read the bearer token from this file (default: a new one)."),
    discovery_timeout: float | None = typer.Option(
        None, "--discovery-timeout", metavar="SECONDS", min=0.1, max=3600,
        help="With --sim: most seconds discovery may take to see the simulated devices start, plug or unplug "
             "(default 60: a busy machine answers late); without: the first search (default 1)."),
    interface: str | None = INTERFACE_OPTION,
    serve_lds: int | None = typer.Option(None, "--serve-lds", metavar="PORT", min=0, max=65535,
                                         help="Without --sim: run a Local Discovery Server on the controller's "
                                              "address at PORT (0: a free one; 4840 is the standard) for the OPC "
                                              "UA devices to register with; they plug and unplug live."),
) -> None:
    """Serve the Generic HMI: the live cell, offered commands, task editor, check/repair, runs.

    Prints the page's URL and the bearer token that requests changing the cell or a run need.

    Exit 0 stopped by Ctrl-C or SIGTERM, 2 bad input (options, a cell, a port it cannot listen on).
    """
    import uvicorn

    from plugnproduce.hmi import create_app
    from plugnproduce.hmi.security import new_token, read_token

    token = read_token(token_file) if token_file else new_token()
    if faults and not sim:
        fail("--faults needs --sim: faults are injected into simulated devices")
    if bin_parts is not None and not sim:
        fail("--bin-parts works on simulated devices: add --sim")
    if serve_lds is not None and sim:
        fail("--serve-lds works without --sim: the simulated devices are found without one")
    address = interface_address(interface)
    if serve_lds:
        _listen(address, serve_lds, "--serve-lds").close()  # a port taken is said now, not when the HMI starts
    source = cell_source(cell, sim, faults, bin_parts, bin_seed, discovery_timeout, address, serve_lds)
    the_cell = cell or (service.builtin("cells", "bin-picking.yaml") if sim else None)
    allowed = list(LOOPBACK_NAMES) if host in LOOPBACK_NAMES else None
    application = create_app(source, runner_for(source, the_cell), token, allowed_hosts=allowed,
                             knowledge=knowledge(the_cell))
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
    if sim and bin_parts is None:
        typer.echo(f"simulated bin: {controller.DEFAULT_BIN_PARTS} parts at random poses (seed {bin_seed}) for the "
                   "runs of tasks that loop on a localized pose; --bin-parts N for another")
    config = uvicorn.Config(application, log_level="warning", timeout_graceful_shutdown=2, lifespan="on", ws="none")
    previous = signal.signal(signal.SIGTERM, _interrupt)  # uvicorn re-raises the signal it stopped on: as Ctrl-C
    try:
        _serve(_server(config, application), sock)  # SIGINT/SIGTERM: a graceful shutdown, then KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
    typer.echo("stopped")
    _leave_busy_workers()


def _server(config: uvicorn.Config, application: FastAPI) -> uvicorn.Server:
    """A uvicorn server that, when it stops, first stops the requests still being worked on (each ends at
    once with 503), so that shutdown neither waits for them nor cancels them with a traceback."""
    import uvicorn

    from plugnproduce.hmi.app import stop_requests

    class Server(uvicorn.Server):
        async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
            stop_requests(application)
            await super().shutdown(sockets)

    return Server(config)


def _interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt


def _serve(server: uvicorn.Server, sock: socket.socket) -> None:
    """Serve until stopped; unlike ``asyncio.run``, never wait for worker threads still busy at the end.

    A request's reasoning or a run's code generation runs in a worker thread and cannot be
    interrupted; ``asyncio.run`` would wait for it to finish before returning.
    """
    loop = (server.config.get_loop_factory() or asyncio.new_event_loop)()
    try:
        loop.run_until_complete(server.serve(sockets=[sock]))
    finally:
        tasks = asyncio.all_tasks(loop)
        for task in tasks:
            task.cancel()
        if tasks:
            loop.run_until_complete(asyncio.gather(*tasks, return_exceptions=True))
        loop.run_until_complete(loop.shutdown_asyncgens())
        loop.close()  # the default executor is shut down without waiting


def _leave_busy_workers() -> None:
    """Exit now if a worker thread is still busy: it would hold the process until its work is done.

    The server has shut down (every run stopped, its journal closed), so nothing is lost.
    """
    busy = [t for t in threading.enumerate() if t is not threading.main_thread() and t.is_alive() and not t.daemon]
    if busy:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)
