"""The use cases behind every interface (CLI, HTTP API, notebooks).

Functions here load descriptions, call the concepts (validation, reasoning, code
generation, execution) and return typed results; they never print.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import secrets
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce import reasoning
from plugnproduce.description.loader import load_cell, load_devices, load_processes, load_task
from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy
from plugnproduce.resources import descriptions_path

if TYPE_CHECKING:  # validation, code generation and execution are imported by the use cases that need them
    from plugnproduce.codegen import GeneratedTask
    from plugnproduce.codegen.outputs import Chart
    from plugnproduce.discovery import LiveCell
    from plugnproduce.executor.journal import RunRecord
    from plugnproduce.executor.run import RecordObserver, RunReport, TaskRun
    from plugnproduce.validation import Report


@dataclass(frozen=True)
class Knowledge:
    """What every use case needs: the taxonomy closure and the known processes."""

    taxonomy: Taxonomy
    processes: tuple[ProcessDescription, ...]

    def process(self, command: str) -> ProcessDescription:
        """The process a command names."""
        for p in self.processes:
            if p.id == command:
                return p
        raise KeyError(command)


@lru_cache(maxsize=8)
def knowledge(processes_dir: Path | None = None) -> Knowledge:
    """The taxonomy (cached by content) and the processes of ``processes_dir`` (default: built-in)."""
    taxonomy = load_taxonomy()
    folder = processes_dir or descriptions_path() / "processes"
    return Knowledge(taxonomy, tuple(load_processes(folder)))


def validate(paths: list[str | Path]) -> Report:
    """Validate description files and folders."""
    from plugnproduce.validation import validate_paths

    return validate_paths(paths, knowledge().taxonomy)


def cell(path: str | Path) -> Cell:
    """Read a cell file."""
    return load_cell(path, knowledge().taxonomy)


def catalogue(folder: str | Path | None = None) -> list[DeviceDescription]:
    """Read a catalogue of device descriptions (default: the built-in devices)."""
    return load_devices(folder or descriptions_path() / "devices", knowledge().taxonomy)


def task(path: str | Path) -> Task:
    """Read a task file."""
    return load_task(path)


def builtin(*parts: str) -> Path:
    """A path inside the built-in descriptions, e.g. ``builtin("cells", "bin-picking.yaml")``."""
    return descriptions_path().joinpath(*parts)



def _as_cell(cell_or_path: Cell | str | Path) -> Cell:
    return cell_or_path if isinstance(cell_or_path, Cell) else cell(cell_or_path)


def _as_task(task_or_path: Task | str | Path) -> Task:
    return task_or_path if isinstance(task_or_path, Task) else task(task_or_path)


def capabilities(cell_or_path: Cell | str | Path) -> reasoning.Capabilities:
    """The process commands a cell offers, with every valid role binding; the others with reasons."""
    k = knowledge()
    return reasoning.capabilities(_as_cell(cell_or_path), k.taxonomy, k.processes)


def check(task_or_path: Task | str | Path, cell_or_path: Cell | str | Path) -> reasoning.CheckResult:
    """Whether a task is plausible in a cell: per step its bindings, device states and problems."""
    k = knowledge()
    return reasoning.check(_as_task(task_or_path), _as_cell(cell_or_path), k.taxonomy, k.processes)


def repair(
    task_or_path: Task | str | Path,
    cell_or_path: Cell | str | Path,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    top: int = 3,
    costs: reasoning.RepairCosts | None = None,
) -> list[reasoning.Repair]:
    """The ``top`` cheapest distinct repairs of an implausible task (none if it is plausible).

    With a catalogue (device descriptions, or a folder of them) a repair may add a device.
    """
    k = knowledge()
    devices = catalogue(catalogue_or_folder) if isinstance(catalogue_or_folder, str | Path) else catalogue_or_folder
    return reasoning.repair(_as_task(task_or_path), _as_cell(cell_or_path), k.taxonomy, k.processes,
                            catalogue=devices, top=top, costs=costs)


def explain_process(cell_or_path: Cell | str | Path, command: str) -> reasoning.ProcessExplanation:
    """Why a process command is (not) offered in a cell."""
    k = knowledge()
    return reasoning.explain_process(_as_cell(cell_or_path), command, k.taxonomy, k.processes)


def explain_step(task_or_path: Task | str | Path, cell_or_path: Cell | str | Path,
                 n: int) -> reasoning.StepExplanation:
    """Why step ``n`` (1-based) of a task is (not) plausible in a cell."""
    k = knowledge()
    return reasoning.explain_step(_as_task(task_or_path), _as_cell(cell_or_path), n, k.taxonomy, k.processes)


def batch(
    configurations: list[reasoning.Configuration] | str | Path,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    tasks: list[Task | str | Path] | None = None,
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
) -> Iterator[reasoning.BatchRow]:
    """Feasibility of many configurations (a list, or a JSONL/CSV file of device lists) of catalogue devices:
    per configuration the offered processes, the plausible tasks, and for the others the cheapest device to add."""
    k = knowledge()
    devices = catalogue_or_folder if isinstance(catalogue_or_folder, list) else catalogue(catalogue_or_folder)
    configs = (configurations if isinstance(configurations, list)
               else reasoning.read_configurations(configurations))
    return reasoning.batch(configs, devices, [_as_task(t) for t in tasks or []], k.taxonomy, k.processes,
                           workers=workers, progress=progress)


def generate_configurations(
    count: int,
    sizes: tuple[int, int],
    seed: int,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
) -> list[reasoning.Configuration]:
    """``count`` random configurations of ``sizes[0]``-``sizes[1]`` distinct catalogue devices."""
    devices = catalogue_or_folder if isinstance(catalogue_or_folder, list) else catalogue(catalogue_or_folder)
    return reasoning.generate(devices, count, sizes, seed)


# ------------------------------------------------------------------ code generation


class ImplausibleTask(PlugNProduceError):
    """A task the plausibility check refuses; ``result`` holds the problems per step."""

    def __init__(self, result: reasoning.CheckResult):
        self.result = result
        super().__init__(f"task {result.task} is not plausible in cell {result.cell}: "
                         + "; ".join(str(p) for p in result.problems))


@dataclass(frozen=True)
class Generated:
    """A task's generated program: the task chart model and every chart written for it."""

    task: GeneratedTask
    charts: list[Chart]


def generate(task_or_path: Task | str | Path, cell_or_path: Cell | str | Path, per_device: bool = False) -> Generated:
    """Check a task, then generate its specific process charts, task chart, closed-world chart and,
    with ``per_device``, each device's program. Raises :class:`ImplausibleTask` for an implausible task."""
    the_task, the_cell = _as_task(task_or_path), _as_cell(cell_or_path)
    result = check(the_task, the_cell)
    if not result.plausible:
        raise ImplausibleTask(result)
    from plugnproduce.codegen import generate_task
    from plugnproduce.codegen.outputs import all_charts

    k = knowledge()
    generated = generate_task(the_task, the_cell, result.bindings(), {p.id: p for p in k.processes}, k.taxonomy)
    return Generated(generated, all_charts(generated, the_cell, per_device))


# ------------------------------------------------------------------ execution


class DevicesMissing(PlugNProduceError):
    """Devices of the cell that discovery did not find."""


def runs_folder() -> Path:
    """Where run journals go unless told otherwise: ``PNP_RUNS``, else ``~/.local/state/plugnproduce/runs``."""
    return Path(os.environ.get("PNP_RUNS") or Path.home() / ".local" / "state" / "plugnproduce" / "runs")


def new_run_id(task_name: str) -> str:
    """A run id that sorts by start time: ``20261123-101500-bin-picking-1a2b``."""
    return f"{time.strftime('%Y%m%d-%H%M%S')}-{task_name}-{secrets.token_hex(2)}"


async def find_devices(live: LiveCell, wanted: list[str], timeout: float) -> Cell:
    """Wait until discovery has found every wanted device; the live cell's devices with their real endpoints."""
    deadline = asyncio.get_running_loop().time() + timeout
    while missing := [d for d in wanted if d not in {x.id for x in live.cell.devices}]:
        left = deadline - asyncio.get_running_loop().time()
        if left <= 0:
            raise DevicesMissing(f"device(s) {', '.join(missing)} of the cell not found on the network "
                                 f"within {timeout:g} s")
        with contextlib.suppress(TimeoutError):
            await live.next_change(left)
    return Cell(live.cell.name, tuple(live.cell.device(d) for d in wanted))


async def run_task(
    task_or_path: Task | str | Path,
    cell_or_path: Cell | str | Path,
    *,
    simulate: bool = False,
    faults: str = "",
    journal: Path | None = None,
    observer: RecordObserver | None = None,
    started: Callable[[TaskRun], None] | None = None,
    discovery_timeout: float = 10.0,
) -> RunReport:
    """Check and generate a task, find the cell's devices by discovery, run the task chart against them.

    With ``simulate`` the cell's devices are simulated for the run, on a private SSDP network,
    with ``faults`` injected (see :func:`plugnproduce.sim.cell.parse_faults`). ``started`` is
    given the run once it exists (to stop it). Raises :class:`ImplausibleTask` before anything runs.
    """
    from plugnproduce.discovery import LiveCell
    from plugnproduce.executor.run import TaskRun
    from plugnproduce.protocols.upnp import network_from_env, private_network
    from plugnproduce.sim.cell import SimulatedCell, parse_faults

    the_task, the_cell = _as_task(task_or_path), _as_cell(cell_or_path)
    generated = generate(the_task, the_cell).task
    journal = journal or runs_folder() / f"{new_run_id(the_task.name)}.jsonl"
    network = private_network() if simulate else network_from_env()
    async with contextlib.AsyncExitStack() as stack:
        if simulate:
            sim = SimulatedCell(the_cell, network=network, faults=parse_faults(faults, the_cell.devices))
            await stack.enter_async_context(sim)
        wanted = [d.id for d in the_cell.devices]
        live = await stack.enter_async_context(LiveCell(knowledge().taxonomy, network=network, name=the_cell.name,
                                                        expected=wanted))
        devices = await find_devices(live, wanted, discovery_timeout)
        run = TaskRun(generated, devices, journal, observer)
        if started is not None:
            started(run)
        follow = asyncio.create_task(_follow_unplugs(live, run))
        try:
            return await run.run()
        finally:
            follow.cancel()


async def _follow_unplugs(live: LiveCell, run: TaskRun) -> None:
    async for change in live.changes():
        if change.kind == "unplug":
            run.device_lost(change.device, "the device left the network (SSDP byebye)")


def report(run: str | Path) -> RunRecord:
    """A run's journal, by path or by run id (in :func:`runs_folder`)."""
    from plugnproduce.executor.journal import read_journal

    path = Path(run)
    if not path.exists() and not path.suffix:
        path = runs_folder() / f"{run}.jsonl"
    return read_journal(path)
