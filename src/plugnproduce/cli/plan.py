"""``pnp plan``: goals in, tasks out.

Exit codes: 0 a plan was found and checked plausible; 1 no plan reaches the goal (with why and what to
buy), or the plan is not plausible (a value the goal fixes is beyond a limit: each problem at the goal's
line); 2 bad input, one ``file:line: message`` line.
"""

from __future__ import annotations

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
    knowledge,
)
from plugnproduce.cli.reasoning import CELL_OPTION, LIVE_OPTION, _cell
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import service
    from plugnproduce.service import Unreachable
else:
    service = lazy_module("plugnproduce.service")


@app.command()
@boundary
def plan(goal: Path = typer.Argument(..., metavar="GOAL", help="The goal file (YAML)."), cell: Path = CELL_OPTION,
         output: Path | None = typer.Option(None, "--output", "-o", metavar="TASK",
                                            help="Write the planned task file here (else it is printed)."),
         pddl: Path | None = typer.Option(None, "--pddl", metavar="DIR",
                                          help="Also write the goal as PDDL (domain.pddl, problem.pddl) into DIR, "
                                               "for other planners; not for a goal with until."),
         live: bool = LIVE_OPTION, discovery_timeout: float | None = DISCOVERY_OPTION,
         interface: str | None = INTERFACE_OPTION,
         minimize: str = typer.Option("steps", "--minimize", metavar="steps|cycle-time",
                                      help="After measuring what the cell can measure: the fewest steps (default), "
                                           "or the least estimated cycle time."),
         json_out: bool = JSON_OPTION) -> None:
    """Plan a task from a goal: which process commands, in which order, on which devices, with which values.

    The plan is the shortest that measures what the cell can measure (a pick pose the bin-picking PC
    reports rather than a default), or with --minimize cycle-time the one of least estimated cycle time;
    it is checked like a written task. Exit 0 planned, 1 no plan reaches the goal (why, and the cheapest
    catalogue device that would make one) or the check refuses the plan (a value the goal fixes is beyond a
    limit; the task is then shown but not written), 2 bad input.
    """
    if minimize not in ("steps", "cycle-time"):
        raise typer.BadParameter(f"--minimize {minimize!r}: expected steps or cycle-time")
    k = knowledge(cell)
    the_cell = _cell(cell, live, discovery_timeout, interface)
    from plugnproduce.service import Link, Unreachable, local_name  # here, not at the top: `pnp --help` loads none

    if pddl is not None:
        domain, problem = service.plan_pddl(goal, the_cell, k)
        pddl.mkdir(parents=True, exist_ok=True)
        (pddl / "domain.pddl").write_text(domain, encoding="utf-8")
        (pddl / "problem.pddl").write_text(problem, encoding="utf-8")
    found = service.plan(goal, the_cell, k, source=str(output) if output else None, minimize=minimize)
    if isinstance(found, Unreachable):
        _unreachable(found, json_out)
        raise typer.Exit(1)
    checked = service.check(found.task, the_cell, k)
    estimate = service.cycle_time(found.task, the_cell, k, checked)
    if not checked.plausible:
        output = None  # a task that check refuses is shown, not written
    if output is not None:
        output.write_text(found.text, encoding="utf-8")
    if json_out:
        emit_json({"goal": found.goal.name, "reachable": True, "steps": found.steps, "task": found.text,
                   "written_to": str(output) if output else None,
                   "defaults_not_measured": [{"step": t, "parameter": n} for t, n in found.blind],
                   "check": checked.to_json(), "minimize": minimize,
                   "cycle_time": estimate.to_json() if estimate is not None else None})
        if not checked.plausible:
            raise typer.Exit(1)
        return
    loop = f", repeated until {local_name(found.goal.until)}" if found.goal.until else ""
    typer.echo(f"goal {found.goal.name} in cell {checked.cell}: planned, {found.steps} steps{loop}; "
               f"the check finds it {'plausible' if checked.plausible else 'implausible'}")
    for step in found.task.one_round()[:found.steps]:
        values = ", ".join(f"{n} from {v.step}.{v.output}" if isinstance(v, Link) else f"{n}={v}"
                           for n, v in step.params.items())
        binding = " ".join(f"{r}={d}" for r, d in step.bind.items())
        typer.echo(f"  {step.index}. {step.command:<16} {binding}" + (f"  ({values})" if values else ""))
    for t, n in found.blind:
        typer.echo(f"  step {t}'s {n} takes its default, though the cell could measure it")
    if estimate is not None:
        typer.echo(f"  estimated cycle time: {estimate.total:.2f} s"
                   + (" per iteration of the loop" if found.goal.until else ""))
    for line in service.goal_findings(found.goal, checked):
        typer.echo(f"  {line}")
    if output is not None:
        typer.echo(f"written to {output}")
    else:
        typer.echo("")
        typer.echo(found.text, nl=False)
    if not checked.plausible:
        raise typer.Exit(1)


def _unreachable(found: Unreachable, json_out: bool) -> None:
    buy = found.purchase
    if json_out:
        emit_json({"goal": found.goal.name, "reachable": False, "reasons": list(found.reasons),
                   "purchase": None if buy is None else {"device": buy.id, "label": buy.label, "cost": buy.cost}})
        return
    typer.echo(f"goal {found.goal.name}: no plan reaches it")
    for r in found.reasons:
        typer.echo(f"  - {r}")
    if buy is not None:
        typer.echo(f"buy {buy.id} ({buy.label}, cost {buy.cost:g}) from the catalogue, and a plan exists")
