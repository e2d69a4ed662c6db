"""``pnp resume``: continue a run that ended by a fault or a stop, re-planned from the devices' states."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import DISCOVERY_OPTION, JSON_OPTION, app, boundary, emit_json, knowledge
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import controller, service
    from plugnproduce.controller import TaskRun
else:
    controller = lazy_module("plugnproduce.controller")
    service = lazy_module("plugnproduce.service")


@app.command()
@boundary
def resume(
    run_id: str = typer.Argument(..., metavar="RUN", help="The run id or journal file of a failed or stopped run "
                                                          "('pnp runs' lists them)."),
    cell: Path | None = typer.Option(None, "--cell", metavar="CELL",
                                     help="The cell file (default: the one the run's journal names)."),
    goal: Path | None = typer.Option(None, "--goal", metavar="GOAL",
                                     help="Plan this goal afresh from the devices' states, instead of the rest of "
                                          "the run's task (for a run of a planned task)."),
    yes: bool = typer.Option(False, "--yes", "-y", help="Continue without asking (for scripts)."),
    sim: bool = typer.Option(False, "--sim", help="Simulate the cell's devices, each started in the state the run "
                                                  "left it in, at the run's speed (for a run of pnp run --sim)."),
    faults: str = typer.Option("", "--faults", metavar="SPEC",
                               help="With --sim: faults to inject, DEVICE:KIND[:NAME[:SECONDS]],..."),
    bin_parts: int | None = typer.Option(None, "--bin-parts", metavar="N", min=0, max=10_000,
                                         help="With --sim: the parts left in the simulated bin (default 5 for a "
                                              "task that loops on a localized pose, else none)."),
    bin_seed: int = typer.Option(0, "--bin-seed", metavar="S", help="With --bin-parts: the seed that places them."),
    journal: Path | None = typer.Option(None, "--journal", metavar="FILE",
                                        help="Journal file of the continuation (default: a new file in PNP_RUNS)."),
    discovery_timeout: float | None = DISCOVERY_OPTION,
    json_out: bool = JSON_OPTION,
) -> None:
    """Resume a run after a fault or an operator's stop: find the cell's devices, ask each its state, re-plan the
    rest of the task (or the goal) from there, show the plan and, once confirmed, run it. With --sim the devices
    are simulated, each started in the state the run left it in.

    The continuation's journal begins with the stop it resumes, the re-plan and who confirmed it.
    Exit 0 the continuation succeeded, 1 it failed, was declined or nothing plausible goes on from the devices'
    states, 2 bad input (no such run, a run that succeeded, devices not found).
    """
    import asyncio  # here, not at the top: the other commands need no event loop
    import signal

    k = knowledge(cell)
    simulate = _simulation(run_id, sim, faults, bin_parts, bin_seed, json_out)

    def confirm(plan: service.Replan) -> str | None:
        _show(plan, json_out)
        if yes:
            return "--yes"
        try:
            return "the operator" if typer.confirm("continue?", default=False, err=True) else None
        except typer.Abort:  # no answer (end of input)
            return None

    def show(record: dict[str, object]) -> None:
        if not json_out:
            typer.echo(service.describe(record))

    def started(the_run: TaskRun) -> None:
        loop = asyncio.get_running_loop()
        for signum in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(signum, the_run.stop)

    try:
        done = asyncio.run(controller.resume_run(run_id, cell, confirm, goal=goal, journal=journal, observer=show,
                                                 started=started, discovery_timeout=discovery_timeout, knowledge=k,
                                                 simulate=simulate))
    except service.NoWayOn as exc:
        typer.echo(f"not resumed: {exc}", err=True)
        for reason in exc.reasons:
            typer.echo(f"  {reason}", err=True)
        raise typer.Exit(1) from None
    _finish(done, json_out)


def _simulation(run_id: str, sim: bool, faults: str, bin_parts: int | None, bin_seed: int,
                json_out: bool) -> controller.SimulatedResume | None:
    """What ``--sim`` asks for; the bin a task that loops on a localized pose gets when none is asked for."""
    if not sim:
        if faults or bin_parts is not None:
            raise typer.BadParameter("--faults and --bin-parts work on simulated devices: add --sim")
        return None
    if bin_parts is None and (bin_parts := controller.default_bin_parts(service.stopped_run(run_id).task)) is not None:
        typer.echo(f"simulated bin: {bin_parts} parts at random poses (seed {bin_seed}); --bin-parts N for another",
                   err=json_out)
    return controller.SimulatedResume(faults, bin_parts, bin_seed)


def _show(plan: service.Replan, json_out: bool) -> None:
    """The plan, before it is confirmed (to stderr with --json, whose stdout is the result)."""
    stopped = plan.stopped
    at = f" at step {stopped.step}" if stopped.step is not None else ""
    lines = [f"run {stopped.run} {stopped.outcome}{at}: {stopped.reason}",
             "the devices report: " + ", ".join(f"{d} {s}" for d, s in sorted(plan.states.items())),
             f"plan: {plan.plan}, {len(plan.task.steps)} step(s)",
             *(f"  repair: {edit}" for edit in plan.repairs), plan.text.rstrip()]
    typer.echo("\n".join(lines), err=json_out)


def _finish(done: controller.Resumed, json_out: bool) -> None:
    report = done.report
    if json_out:
        emit_json({"stopped": done.replan.stopped.record(), "replan": done.replan.record(),
                   "continued": report is not None, **({"run": report.to_json()} if report else {})})
    if report is None:
        typer.echo("not resumed: the plan was not confirmed; nothing was sent", err=True)
        raise typer.Exit(1)
    if not json_out:
        typer.echo(f"{report.outcome}; journal {report.journal}")
        if report.fault is not None:
            typer.echo(f"fault: {report.fault}")
    if report.outcome != "succeeded":
        raise typer.Exit(1)
