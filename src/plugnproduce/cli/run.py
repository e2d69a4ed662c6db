"""``pnp run`` and ``pnp report``: run a task on the cell's devices, and read a run's journal."""

from __future__ import annotations

import signal
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import (
    DISCOVERY_OPTION,
    INTERFACE_OPTION,
    JSON_OPTION,
    app,
    boundary,
    emit_json,
    interface_address,
    knowledge,
)
from plugnproduce.cli.console.progress import Phases, on_a_terminal
from plugnproduce.cli.generate import refuse
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    import asyncio

    from plugnproduce import controller, service
    from plugnproduce.controller import TaskRun
else:
    asyncio = lazy_module("asyncio")  # the event loop is started by the commands that use it
    controller = lazy_module("plugnproduce.controller")
    service = lazy_module("plugnproduce.service")


@app.command()
@boundary
def run(
    task: Path = typer.Argument(..., metavar="TASK", help="The task file (YAML)."),
    cell: Path | None = typer.Option(None, "--cell", metavar="CELL",
                                     help="The cell file (default with --sim: the bin-picking cell)."),
    sim: bool = typer.Option(False, "--sim", help="Simulate the cell's devices for this run (on loopback, or "
                                                  "--interface, on a private SSDP port)."),
    faults: str = typer.Option("", "--faults", metavar="SPEC",
                               help="With --sim: faults to inject, DEVICE:KIND[:NAME[:SECONDS]],..."),
    bin_parts: int | None = typer.Option(None, "--bin-parts", metavar="N", min=0, max=10_000,
                                         help="With --sim: a simulated bin of N parts at random poses (default "
                                              "5 for a task that loops on a localized pose, else none)."),
    bin_seed: int = typer.Option(0, "--bin-seed", metavar="S", help="With --bin-parts: the seed that places them."),
    speed: float = typer.Option(1.0, "--speed", metavar="F", min=0.01, max=1000.0,
                                help="With --sim: the devices work F times faster than real time (their durations "
                                     "divided by F; default 1, real time)."),
    journal: Path | None = typer.Option(None, "--journal", metavar="FILE",
                                        help="Journal file (default: a new file in PNP_RUNS)."),
    assume_initial: bool = typer.Option(False, "--assume-initial",
                                        help="Plan from the charts' initial states, not the states the devices "
                                             "report."),
    discovery_timeout: float | None = DISCOVERY_OPTION,
    json_out: bool = JSON_OPTION,
    interface: str | None = INTERFACE_OPTION,
) -> None:
    """Find the devices, ask each its state, check and generate the task from there, run it, and journal every
    command and event.

    Exit 0 the task succeeded, 1 it failed or is implausible (with the report), 2 bad input.
    A fault, Ctrl-C or SIGTERM stops the run safely: no further task command; each device is sent the safe-stop
    request its state takes, and the journal ends with each device's answer and state, then the end record.
    """
    address = interface_address(interface)
    if cell is None:
        if not sim:
            raise typer.BadParameter("give --cell CELL, or --sim to run on the simulated bin-picking cell")
        cell = service.builtin("cells", "bin-picking.yaml")
    if bin_parts is not None and not sim:
        raise typer.BadParameter("--bin-parts works on simulated devices: add --sim")
    if speed != 1.0 and not sim:
        raise typer.BadParameter("--speed works on simulated devices: add --sim")
    if sim and bin_parts is None and (bin_parts := controller.default_bin_parts(task)) is not None:
        typer.echo(f"simulated bin: {bin_parts} parts at random poses (seed {bin_seed}); --bin-parts N for another",
                   err=json_out)

    phases = Phases(on_a_terminal(json_out))

    def show(record: dict[str, object]) -> None:
        if record["kind"] == "step":
            phases.update(f"step {record.get('step')} ({record.get('command')})")
        if not json_out:
            phases.echo(service.describe(record))

    def started(the_run: TaskRun) -> None:
        loop = asyncio.get_running_loop()
        for signum in (signal.SIGINT, signal.SIGTERM):  # a supervisor stops with SIGTERM, a terminal with Ctrl-C
            loop.add_signal_handler(signum, the_run.stop)

    try:
        with phases:
            report = asyncio.run(controller.run_task(task, cell, simulate=sim, faults=faults, journal=journal,
                                                  observer=show, started=started, progress=phases,
                                                  knowledge=knowledge(cell), bin_parts=bin_parts, bin_seed=bin_seed,
                                                  assume_initial=assume_initial, speed=speed,
                                                  discovery_timeout=discovery_timeout, interface=address))
            phases.close(last_done=True)
    except service.ImplausibleTask as exc:
        refuse(exc, "not run", json_out)
    if json_out:
        emit_json(report.to_json())
    else:
        typer.echo(f"{report.outcome}; journal {report.journal}")
        if report.fault is not None:
            typer.echo(f"fault: {report.fault}")
    if report.fault is not None and report.fault.kind == "journal":  # the journal cannot tell of it: say it here
        typer.echo(f"error: {report.fault.message}; the run was stopped safely, its journal ends before the stop",
                   err=True)
    if report.outcome != "succeeded":
        raise typer.Exit(1)


@app.command()
@boundary
def report(run_id: str | None = typer.Argument(None, metavar="RUN", help="A run id or a journal file "
                                               "(default: the latest run; 'pnp runs' lists them)."),
           json_out: bool = JSON_OPTION) -> None:
    """Print a run from its journal: every step, command, event and state, and how it ended (or that it crashed).

    Exit 0 printed (however the run ended), 2 no such run or an unreadable journal.
    """
    record = service.report(run_id)
    if json_out:
        emit_json({"journal": str(record.path), "status": record.status, "safe_stop": record.safe_stop,
                   "records": record.records})
        return
    for r in record.records:
        typer.echo(service.describe(r))
    typer.echo(f"status: {record.status}" + (f"; {record.safe_stop}" if record.safe_stop else ""))
