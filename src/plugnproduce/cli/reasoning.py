"""``pnp capabilities``, ``pnp check``, ``pnp repair``, ``pnp explain`` and ``pnp batch``.

Exit codes: 0 ok (offered, plausible, repaired, batch done); 1 a finding (implausible
task, process not offered, no repair found); 2 bad input, one ``file:line: message`` line.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import sys
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

import typer

from plugnproduce.cli.application import (
    DISCOVERY_OPTION,
    INTERFACE_OPTION,
    JSON_OPTION,
    LIBRARIES,
    app,
    boundary,
    emit_json,
    fail,
    interface_address,
    knowledge,
)
from plugnproduce.cli.console.progress import on_a_terminal
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import controller, service
    from plugnproduce.service import Cell
else:
    controller = lazy_module("plugnproduce.controller")
    service = lazy_module("plugnproduce.service")

CELL_OPTION = typer.Option(..., "--cell", metavar="CELL", help="The cell file (YAML).")
LIVE_OPTION = typer.Option(False, "--live", help="Find the cell's devices on the network and start from the state "
                                                 "each reports, not from its chart's initial state.")


def _cell(cell: Path, live: bool, discovery_timeout: float | None, interface: str | None = None) -> Path | Cell:
    """The cell file, or with ``live`` the cell with each device (found on ``interface``) in the state it reports."""
    if not live:
        if interface is not None:
            fail("--interface works with --live: it is where the cell's devices are found")
        return cell
    import asyncio

    address = interface_address(interface)
    return asyncio.run(controller.live_cell(cell, knowledge(cell), discovery_timeout or controller.DISCOVERY_SECONDS,
                                            interface=address))
VERBOSE_OPTION = typer.Option(False, "--verbose", "-v",
                              help="The engineer's view: ontology terms, rule instances, axioms and file:line.")


def _bindings(bindings: tuple[dict[str, str], ...]) -> str:
    return " | ".join(" ".join(f"{r}={d}" for r, d in b.items()) for b in bindings)


def _reasons(reasons: tuple[service.Reason, ...], verbose: bool, indent: str = "    ") -> None:
    for r in reasons:
        typer.echo(f"{indent}- {r.text if verbose else r.plain}")
        if r.where and verbose:
            typer.echo(f"{indent}  rests on: {', '.join(str(w) for w in r.where)}")


@app.command()
@boundary
def capabilities(cell: Path = CELL_OPTION, verbose: bool = VERBOSE_OPTION, json_out: bool = JSON_OPTION,
                 all_bindings: bool = typer.Option(False, "--all-bindings",
                                                   help="List every valid role binding, not just one.")) -> None:
    """Show the process commands a cell offers and why the others are not offered.

    Each offered command shows one valid role binding and how many there are (every one with
    --all-bindings); with --json also the devices that can fill each role.

    Exit 0 answered (whatever is offered), 2 bad input.
    """
    caps = service.capabilities(cell, knowledge(cell), all_bindings)
    if json_out:
        emit_json(caps.to_json())
        return
    total = len(caps.offered) + len(caps.not_offered)
    typer.echo(f"cell {caps.cell}: {len(caps.offered)} of {total} process commands offered")
    for o in caps.offered:
        more = "" if all_bindings or o.binding_count == 1 else f"  (1 of {o.binding_count:,} bindings)"
        typer.echo(f"  {o.command:<16} {_bindings(o.bindings)}{more}")
    if caps.not_offered:
        typer.echo("not offered:")
    for n in caps.not_offered:
        typer.echo(f"  {n.command}")
        _reasons(n.reasons, verbose)


def _print_problems(result: service.CheckResult, verbose: bool) -> None:
    for p in result.problems:
        typer.echo(str(p) if verbose else f"{p.where}: {p.reason.plain}")
        if p.reason.where and verbose:
            typer.echo(f"    rests on: {', '.join(str(w) for w in p.reason.where)}")


def _cycle_line(estimate: service.CycleTime) -> str:
    """The text output's total line: the estimated cycle time, and what it counts once."""
    line = f"estimated cycle time: {estimate.total:.2f} s"
    per = [f"{lp.later_iteration:.2f} s per further iteration of steps {lp.entry}-{lp.last}"
           for lp in estimate.loops if lp.count is None]
    return line + (f" (loops ended by an outcome counted once; {', '.join(per)})" if per else "")


@app.command()
@boundary
def check(task: Path = typer.Argument(..., metavar="TASK", help="The task file (YAML)."), cell: Path = CELL_OPTION,
          live: bool = LIVE_OPTION, discovery_timeout: float | None = DISCOVERY_OPTION,
          interface: str | None = INTERFACE_OPTION, verbose: bool = VERBOSE_OPTION,
          json_out: bool = JSON_OPTION) -> None:
    """Check that a task is plausible: each step finds its devices in the states it starts from.

    Exit 0 plausible, 1 implausible (each problem names the step, device, its state and the needed state),
    2 bad input.
    """
    the_cell, k = _cell(cell, live, discovery_timeout, interface), knowledge(cell)
    result = service.check(task, the_cell, k)
    estimate = service.cycle_time(task, the_cell, k, result) if result.plausible else None
    if json_out:
        emit_json({**result.to_json(), "cycle_time": estimate.to_json() if estimate is not None else None})
    else:
        verdict = "plausible" if result.plausible else f"implausible ({len(result.problems)} problem(s))"
        typer.echo(f"task {result.task} in cell {result.cell}: {verdict}")
        _print_problems(result, verbose)
        for link in result.links:  # what a device reports is proven here or held to the contract when it comes
            typer.echo(f"  {link}")
        if estimate is not None:
            typer.echo(_cycle_line(estimate))
    if not result.plausible:
        raise typer.Exit(1)


@app.command()
@boundary
def repair(
    task: Path = typer.Argument(..., metavar="TASK", help="The task file (YAML)."),
    cell: Path = CELL_OPTION,
    catalogue: Path | None = typer.Option(None, "--catalogue", metavar="DIR",
                                          help="Devices a repair may add (a folder)."),
    top: int = typer.Option(3, "--top", min=1, max=20, metavar="K",
                            help="How many distinct repairs: fewest side effects first, then cheapest."),
    live: bool = LIVE_OPTION,
    discovery_timeout: float | None = DISCOVERY_OPTION,
    interface: str | None = INTERFACE_OPTION,
    verbose: bool = VERBOSE_OPTION,
    rank: str = typer.Option("side-effects", "--rank", metavar="side-effects|time",
                             help="Order the repairs by their side effects, then cost (default), or by the cycle "
                                  "time they add (the repaired task's estimate), fastest first."),
    json_out: bool = JSON_OPTION,
) -> None:
    """Propose minimal-cost repairs of an implausible task: ranked edit lists and the resulting tasks.

    Ranked by their worst side effect (none first, a dropped part last), then by cost, cheapest first (or with
    --rank time by the estimated cycle time of the repaired task); each one
    checked again, with the devices it buys and their own limits.
    A task of more than 40 steps is repaired window by window around its problems (same optimal cost).
    Exit 0 when the task is plausible or repairs were found, 1 when no repair exists, 2 bad input.
    """
    if rank not in ("side-effects", "time"):
        raise typer.BadParameter(f"--rank {rank!r}: expected side-effects or time")
    the_cell = _cell(cell, live, discovery_timeout, interface)
    the_task = service.task(task)  # read once, checked once: the repairs' assessment starts from this check
    result = service.check(the_task, the_cell, knowledge(cell))
    repairs = [] if result.plausible else service.assessed_repairs(the_task, the_cell, catalogue, top,
                                                                   knowledge(cell), checked=result)
    times = service.repair_cycle_times(repairs, the_cell, catalogue, knowledge(cell))
    if rank == "time":
        order = sorted(range(len(repairs)), key=lambda i: (_seconds(times[i]), repairs[i].rank))
        repairs = [dataclasses.replace(repairs[i], rank=n) for n, i in enumerate(order, start=1)]
        times = [times[i] for i in order]
    players = service.catalogue_players(result, knowledge(cell))
    if json_out:
        emit_json({"task": result.task, "cell": result.cell, "plausible": result.plausible,
                   "repairs": [{**r.to_json(), "cycle_time": _seconds(t, None)} for r, t in zip(repairs, times,
                                                                                            strict=True)],
                   "catalogue_players": [{"step": i, "role": r, "devices": ds} for (i, r), ds in players.items()]})
    elif result.plausible:
        typer.echo(f"task {result.task} in cell {result.cell}: plausible; nothing to repair")
    else:
        typer.echo(f"task {result.task} in cell {result.cell}: implausible; {len(repairs)} repair(s)")
        _print_problems(result, verbose)
        for (i, role), devices in players.items():
            typer.echo(f"step {i}, role '{role}': " + (f"catalogue device(s) that could play it: {', '.join(devices)}"
                                                       + ("" if catalogue else " (repair with --catalogue to add one)")
                                                       if devices else "no catalogue device (built-in or library) "
                                                       "can play it"))
        for r, t in zip(repairs, times, strict=True):
            typer.echo(f"\nrepair {r.rank} (cost {r.repair.cost:g}):")
            for e in r.repair.edits:
                typer.echo(f"  - {e.text} [cost {e.cost:g}]")
            for x in r.side_effects:
                typer.echo(f"  side effect: {x.text}")
            if r.repair.unrolls:
                typer.echo(f"  note: {r.repair.unrolls}")
            if t is not None:
                typer.echo(f"  estimated cycle time: {t.total:.2f} s")
            typer.echo("  resulting task:")
            typer.echo("".join(f"    {line}\n" for line in service.task_text(r.repair.task).splitlines()), nl=False)
    if not result.plausible and not repairs:
        raise typer.Exit(1)


def _seconds(estimate: service.CycleTime | None, missing: float | None = float("inf")) -> float | None:
    """A repaired task's estimated seconds (``missing`` when it has none)."""
    return round(estimate.total, 3) if estimate is not None else missing


def _tree(ex: service.Explanation, depth: int | None, verbose: bool) -> None:
    for level, sentence in ex.derivation.sentences(depth, verbose):
        typer.echo(f"{'  ' * level}{'- ' if level else ''}{sentence}")
    if ex.counterfactuals:
        typer.echo("what would turn the answer around (each confirmed by the reasoner):" if ex.answer is False
                   else "what it rests on (each confirmed by the reasoner):")
        for c in ex.counterfactuals:
            typer.echo(f"  - {c.text}")
            for effect in c.side_effects:
                typer.echo(f"    side effect: {effect}")
    elif ex.none_exists:
        typer.echo(f"no counterfactual: {ex.none_exists}")


@app.command()
@boundary
def explain(
    target: str = typer.Argument(..., metavar="TARGET", help="A process command, or with --step a task file."),
    cell: Path = CELL_OPTION,
    step: int | None = typer.Option(None, "--step", metavar="N",
                                    help="Explain this step (1-based) of the task TARGET."),
    depth: int | None = typer.Option(None, "--depth", min=0, metavar="N",
                                     help="Print the derivation this many levels deep (default: all)."),
    verbose: bool = VERBOSE_OPTION,
    catalogue: Path | None = typer.Option(None, "--catalogue", metavar="DIR",
                                          help="Devices a counterfactual may add (default: the libraries' devices)."),
    language: str = typer.Option("en", "--lang", metavar="TAG", help="Language of the ontology labels."),
    json_out: bool = JSON_OPTION,
) -> None:
    """Why a process command is (not) offered, or why a task's step is (not) plausible: a derivation through the
    rules, the ontology and the state charts, printed as sentences (deepest cause last), and the changes the
    reasoner confirms would turn the answer around.

    Exit 0 when the answer is yes, 1 when it is no, 2 bad input.
    """
    if step is None and (Path(target).suffix in {".yaml", ".yml"} or Path(target).is_file()):
        fail(f"{target} is a task file: name the step to explain, pnp explain {target} --cell {cell} --step N "
             "(without --step, TARGET is a process command such as pick)")
    if step is None:
        ex = service.explain_process(cell, target, knowledge(cell))
        why = service.explain_offered(cell, target, knowledge(cell), catalogue, language)
        payload = {**ex.to_json(), **why.to_json()}
    else:
        st = service.explain_step(Path(target), cell, step, knowledge(cell))
        why = service.explain_plausible(Path(target), cell, step, knowledge(cell), language)
        payload = {**st.to_json(), **why.to_json()}
    if json_out:
        emit_json(payload)
    else:
        _tree(why, depth, verbose)
    if not why.answer:
        raise typer.Exit(1)


def _sizes(text: str) -> tuple[int, int]:
    low, _, high = text.partition("-")
    try:
        return int(low), int(high or low)
    except ValueError:
        fail(f"--sizes: expected MIN-MAX such as 2-6; found {text!r}")


BATCH_HELP = """Feasibility of many cell configurations: offered processes, plausible tasks, cheapest purchases.

CONFIGS is a JSONL file (or - for standard input), one configuration a line:
{"config": "cell-1", "devices": ["robot", "gripper"]}, devices by their catalogue ids; or a CSV
file with columns config, devices (space separated). Configurations are read and answered one
chunk at a time, so a file of millions of lines needs no more memory than a small one.

Output (stdout or -o FILE): one JSON line per configuration, in input order:
{"config", "devices", "offered", "plausible", "purchase"}. "purchase" is null when every --task
is plausible; otherwise {"options": [{"add": [DEVICE, ...], "cost": N}, ...]}, the --top cheapest
sets of catalogue devices (pnp:cost; ties: fewer devices) whose addition makes every task
plausible; {"options": [], "ambiguous": "..."} when several devices of the configuration can
play a step's role (bind it in the task: no purchase cures that); {"options": [], "impossible":
"why"} when no set from the catalogue helps. A .csv output file gets the same columns as CSV.
With -o, or on a terminal, a last line on stderr counts the configurations of each kind.
--cycle-time adds "cost" and per task its estimated "cycle_time" (seconds, null where not plausible);
--pareto prints only the front of cost x cycle time: {"config", "devices", "cost", "cycle_time"}.

Exit 0 answered (whatever is feasible), 2 bad input.
"""


@app.command(help=BATCH_HELP)
@boundary
def batch(
    configs: str | None = typer.Argument(None, metavar="CONFIGS",
                                         help="Configurations: JSONL ({\"config\", \"devices\"}), CSV, or - (stdin)."),
    generate: int | None = typer.Option(None, "--generate", metavar="N",
                                        help="Generate this many random configurations."),
    sizes: str = typer.Option("2-6", "--sizes", metavar="MIN-MAX",
                              help="Devices per generated configuration, MIN-MAX."),
    seed: int = typer.Option(1, "--seed", metavar="N", help="Seed of the generator."),
    catalogue: Path | None = typer.Option(None, "--catalogue", metavar="DIR",
                                          help="Device folder (default: the libraries' devices)."),
    tasks: list[Path] = typer.Option([], "--task", metavar="TASK",
                                     help="A task to check in every configuration (repeatable)."),
    top: int = typer.Option(1, "--top", min=1, max=100, metavar="K",
                            help="Cheapest purchases to list per configuration."),
    output: Path | None = typer.Option(None, "-o", "--output", metavar="FILE",
                                       help="Report file: .jsonl or .csv (default: stdout, JSONL)."),
    workers: int = typer.Option(2, "--workers", min=1, metavar="N",
                                help="Worker processes, for the configurations beyond the first 100,000."),
    cluster: str | None = typer.Option(None, "--cluster", metavar="ADDRESS",
                                       help="Run on a Dask cluster: tcp://HOST:8786, tls://HOST:8786, or local:N "
                                            "worker processes. The cluster runs what the batch sends it: give "
                                            "only an address you trust as you trust your own machine."),
    cluster_timeout: float = typer.Option(10.0, "--cluster-timeout", metavar="SECONDS", min=0.1, max=3600,
                                          help="Most seconds connecting to the cluster may take."),
    cluster_ca: Path | None = typer.Option(None, "--cluster-ca", metavar="FILE",
                                           help="With tls://: the CA certificate the scheduler's is signed by."),
    cluster_cert: Path | None = typer.Option(None, "--cluster-cert", metavar="FILE",
                                             help="With tls://: this client's certificate."),
    cluster_key: Path | None = typer.Option(None, "--cluster-key", metavar="FILE",
                                            help="With tls://: this client's private key."),
    cycle_time: bool = typer.Option(False, "--cycle-time",
                                    help="Add each configuration's cost and per task its estimated cycle time "
                                         "(seconds), answered in this process (JSONL)."),
    pareto: bool = typer.Option(False, "--pareto",
                                help="Print only the configurations on the front of cost x cycle time (every task "
                                     "plausible; the time summed over the tasks), cheapest first (JSONL)."),
) -> None:
    if (configs is None) == (generate is None):
        fail("give either CONFIGS (a JSONL or CSV file, or -) or --generate N")
    access = None
    if cluster is not None:
        access = service.ClusterAccess(cluster, cluster_timeout, cluster_ca, cluster_cert, cluster_key)
        try:
            service.check_cluster_address(cluster)
            access.check()
        except ValueError as exc:
            fail(f"--cluster: {exc}")
    engine = service.batch_engine(catalogue, list(tasks), top, tuple(LIBRARIES["folders"]), LIBRARIES["builtin"])
    total: int | None = generate
    if generate is not None:
        try:
            configurations = service.random_configurations(engine.devices, generate, _sizes(sizes), seed)
        except ValueError as exc:
            fail(f"--sizes: {exc}")
    elif configs == "-":
        configurations = service.configurations_from(service.bounded_lines(sys.stdin), "<stdin>")
    else:
        configurations = service.read_configurations(configs)  # type: ignore[arg-type]
    as_csv = output is not None and output.suffix.lower() == ".csv"
    if cycle_time or pareto:
        if as_csv or cluster is not None:
            fail("--cycle-time and --pareto write JSONL in this process: no .csv output, no --cluster")
        _timed(engine, configurations, catalogue, list(tasks), output, pareto)
        return
    with contextlib.ExitStack() as stack:
        out = stack.enter_context(output.open("w", encoding="utf-8", newline="")) if output else sys.stdout
        if as_csv:
            import csv

            csv.writer(out, lineterminator="\n").writerow(service.BATCH_CSV_HEADER)
        tally: dict[str, int] = {}
        written = _write(lambda progress: service.batch_report_from(
            engine, configurations, "csv" if as_csv else "jsonl", workers, progress, cluster=access, tally=tally),
            out, total)
    if output is not None or on_a_terminal():
        where = f" to {output}" if output is not None else ""
        typer.echo(f"wrote {written} configurations{where}: {_tally(tally)}", err=True)


def _timed(engine: service.Engine, configurations: Iterable[service.Configuration], catalogue: Path | None,
           tasks: list[Path], output: Path | None, pareto: bool) -> None:
    """``pnp batch --cycle-time`` (every row with its cost and cycle times) or ``--pareto`` (the front only)."""
    rows = service.batch_cycle_times(engine, configurations, catalogue, list(tasks), tuple(LIBRARIES["folders"]),
                                     LIBRARIES["builtin"])
    with contextlib.ExitStack() as stack:
        out = stack.enter_context(output.open("w", encoding="utf-8")) if output else sys.stdout
        if not pareto:
            for row in rows:
                out.write(json.dumps(row) + "\n")
            return
        for point in service.pareto_front(rows):
            out.write(json.dumps(point) + "\n")


def _tally(tally: dict[str, int]) -> str:
    """``3 all tasks plausible, 5 with a purchase, 2 ambiguous (bind a role), 1 impossible``."""
    words = {"plausible": "all tasks plausible", "buy": "with a purchase", "ambiguous": "ambiguous (bind a role)",
             "impossible": "impossible"}
    return ", ".join(f"{tally.get(k, 0)} {w}" for k, w in words.items())


def _write(report: Callable[[Callable[[int], None]], Iterator[str]], out: TextIO, total: int | None) -> int:
    """Write the report as it comes, with a progress bar on a terminal; the number of configurations written."""
    if not on_a_terminal():  # no bar to show: rich is not even imported
        written = 0

        def count(n: int) -> None:
            nonlocal written
            written += n

        for text in report(count):
            out.write(text)
        return written
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("batch"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    written = 0
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        job = bar.add_task("batch", total=total)

        def advance(n: int) -> None:
            nonlocal written
            written += n
            bar.update(job, completed=written)

        for text in report(advance):
            out.write(text)
    return written
