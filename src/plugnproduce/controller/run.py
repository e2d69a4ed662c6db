"""Runs of a task on a cell's devices: find them by discovery, ask their states, run the task chart.

The async half of the use cases: what talks to devices over the network (discovery, XIRP, UPnP)
and to simulated devices. The sync use cases it builds on (check, generate, :func:`~plugnproduce.service.plan_run`)
are the service's.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from plugnproduce.description.model import Cell, DeviceDescription, Link, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.knowledge import Knowledge
from plugnproduce.service import CellArg, TaskArg, as_task, cell_and_knowledge, new_run_id, plan_run, runs_folder

if TYPE_CHECKING:
    from plugnproduce.codegen import GeneratedTask
    from plugnproduce.discovery import LiveCell
    from plugnproduce.executor.report import RunReport
    from plugnproduce.executor.run import RecordObserver, TaskRun
    from plugnproduce.protocols.upnp import SsdpNetwork
    from plugnproduce.sim.cell import SimulatedCell


class DevicesMissing(PlugNProduceError):
    """Devices of the cell that discovery did not find."""


DISCOVERY_SECONDS = 10.0
"""How long a run or a live check waits for the cell's devices on the network, unless told."""
SIMULATED_DISCOVERY_SECONDS = 60.0
"""The same for the devices a run simulates itself: they are up, so only a busy machine delays their answers."""

DEFAULT_BIN_PARTS = 5
"""Parts in the simulated bin (placed by seed 0 unless told) that a simulated run of a task taking a reported
value gets when no bin is asked for (``--bin-parts``)."""


def default_bin_parts(task_or_path: TaskArg) -> int | None:
    """How many parts a simulated bin needs for a run of this task when none was asked for:
    :data:`DEFAULT_BIN_PARTS` when the task loops until (or while) an outcome and a step takes a value another
    step reports (a data link, such as the pose where a localisation found a part), so that the parts it finds
    are taken out and the loop ends when the bin is empty; None for any other task (the simulated devices report
    their charts' values, and a bin would refuse a move to a fixed pose where no part lies)."""
    the_task = as_task(task_or_path)
    takes = any(isinstance(v, Link) for step in the_task.steps for v in step.params.values())
    waits = any(loop.until or loop.while_outcome for loop in the_task.loops)
    return DEFAULT_BIN_PARTS if takes and waits else None


async def find_devices(live: LiveCell, wanted: list[str], timeout: float) -> Cell:
    """Wait until discovery has found every wanted device; the live cell's devices with their real endpoints."""
    deadline = asyncio.get_running_loop().time() + timeout
    while missing := [d for d in wanted if d not in {x.id for x in live.cell.devices}]:
        left = deadline - asyncio.get_running_loop().time()
        if left <= 0:
            raise DevicesMissing(f"device(s) {', '.join(missing)} of the cell not found on the network "
                                 f"within {timeout:g} s{_refusals(live)}")
        with contextlib.suppress(TimeoutError):
            await live.next_change(left)
    return Cell(live.cell.name, tuple(live.cell.device(d) for d in wanted))


def _refusals(live: LiveCell) -> str:
    """What discovery refused meanwhile (a device, a Local Discovery Server), the latest three, as the end of the
    line that says what is missing: a device refused may be one of them, an LDS refused may have listed them."""
    said = [r.reason if r.udn == r.location else f"{r.udn} at {r.location}: {r.reason}"
            for r in list(live.refused.values())[-3:]]
    return "".join(f"; refused {s}" for s in said)


async def run_task(
    task_or_path: Task | str | Path,
    cell_or_path: Cell | str | Path,
    *,
    simulate: bool = False,
    faults: str = "",
    journal: Path | None = None,
    observer: RecordObserver | None = None,
    started: Callable[[TaskRun], None] | None = None,
    discovery_timeout: float | None = None,
    progress: Callable[[str], None] | None = None,
    knowledge: Knowledge | None = None,
    bin_parts: int | None = None,
    bin_seed: int = 0,
    assume_initial: bool = False,
    interface: str | None = None,
    speed: float = 1.0,
) -> RunReport:
    """Check and generate a task, find the cell's devices by discovery, run the task chart against them.

    With ``simulate`` the cell's devices are simulated for the run, on a private SSDP network,
    with ``faults`` injected (see :func:`plugnproduce.sim.cell.parse_faults`), working on a
    simulated bin of ``bin_parts`` parts placed by ``bin_seed`` if given. ``started`` is
    given the run once it exists (to stop it); ``discovery_timeout`` bounds the wait for the devices
    (default :data:`DISCOVERY_SECONDS`, simulated: :data:`SIMULATED_DISCOVERY_SECONDS`); ``progress`` is told
    each phase as it begins (checking, generating, starting devices, discovering, running). The task is
    checked and generated from the state each device reports once discovered (:func:`reported_states`), or, with
    ``assume_initial``, from the charts' initial states before discovery. ``interface`` (a name or an address,
    default ``PNP_INTERFACE``, else loopback) is where the devices are found and spoken to, the simulated ones too.
    Simulated devices work ``speed`` times faster than real time (their durations divided by it).
    Raises :class:`ImplausibleTask` before any command goes out.
    """
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.interface import chosen_address
    from plugnproduce.protocols.opcua.spec import chosen_lds
    from plugnproduce.protocols.upnp import LOOPBACK, network_from_env, private_network

    say = progress or (lambda _: None)
    the_task, (the_cell, k) = as_task(task_or_path), cell_and_knowledge(cell_or_path, knowledge)
    generated: GeneratedTask | None = None
    if assume_initial:
        say("checking the task in the cell")
        generated = plan_run(the_task, the_cell, k, progress=say)
    journal = journal or runs_folder() / f"{new_run_id(the_task.name)}.jsonl"
    network = private_network(chosen_address(interface)) if simulate else network_from_env(interface)
    async with contextlib.AsyncExitStack() as stack:
        if simulate:
            where = "loopback" if network.interface == LOOPBACK.interface else network.interface
            say(f"starting {len(the_cell.devices)} simulated device(s) on {where}")
            await stack.enter_async_context(_simulated(the_cell, network, faults, bin_parts, bin_seed, speed))
        simulated = speed if simulate else None
        say(f"discovering devices: {', '.join(d.id for d in the_cell.devices)}")
        wanted = [d.id for d in the_cell.devices]
        live = await stack.enter_async_context(LiveCell(k.taxonomy, network=network, name=the_cell.name,
                                                        expected=wanted, lds=None if simulate else chosen_lds()))
        devices = await find_devices(live, wanted, discovery_timeout or (SIMULATED_DISCOVERY_SECONDS if simulate
                                                                         else DISCOVERY_SECONDS))
        run = await planned_run(the_task, the_cell, devices, journal, knowledge=k, observer=observer,
                                progress=say, generated=generated, speed=simulated)
        if started is not None:
            started(run)
        follow = asyncio.create_task(_follow_unplugs(live, run))
        try:
            return await run.run()
        finally:
            follow.cancel()


def _simulated(cell: Cell, network: SsdpNetwork, faults: str, bin_parts: int | None, bin_seed: int,
               speed: float = 1.0) -> SimulatedCell:
    """The devices of ``cell`` simulated on ``network``, with ``faults``, on a bin of ``bin_parts`` parts if given,
    ``speed`` times faster than real time."""
    from plugnproduce.sim.bin import SimulatedBin
    from plugnproduce.sim.cell import SimulatedCell, parse_faults

    parts = SimulatedBin(bin_parts, bin_seed) if bin_parts is not None else None
    return SimulatedCell(cell, network=network, faults=parse_faults(faults, cell.devices), bin=parts, speed=speed)


async def planned_run(task: Task, cell: Cell, devices: Cell, journal: Path, *, knowledge: Knowledge | None = None,
                      observer: RecordObserver | None = None, progress: Callable[[str], None] | None = None,
                      generated: GeneratedTask | None = None, speed: float | None = None) -> TaskRun:
    """The run of ``task`` in ``cell`` on ``devices`` (its devices at the endpoints discovery found), journalling
    into ``journal``: checked and generated from the state each device reports (:func:`reported_states`), unless
    ``generated`` is the task planned already; it starts when its ``run()`` is awaited. ``speed``: the speed factor
    of simulated devices, journalled with the start (None: real devices).

    Every run starts here: ``pnp run`` (:func:`run_task`) and the HMI's (:class:`~.runner.ExecutorRunner`).
    Raises :class:`StateNotReported` or :class:`~plugnproduce.service.ImplausibleTask` before any command goes out.
    """
    the_cell, k = cell_and_knowledge(cell, knowledge)
    if generated is None:
        if progress is not None:
            progress("asking each device its state; checking the task from there")
        reported = the_cell.reported(await reported_states(devices))
        generated = await asyncio.to_thread(plan_run, task, reported, k, progress)
    if progress is not None:
        progress("running")
    named = Cell(devices.name, devices.devices, devices.file or the_cell.file)  # the cell file is journalled
    return start_run(generated, named, journal, observer, prefixes=k.prefixes, speed=speed)


class StateNotReported(PlugNProduceError):
    """A device of a live cell did not report its state."""


async def reported_states(devices: Cell, timeout: float | None = None) -> dict[str, str]:
    """Ask every device of a live cell (``devices``: their real endpoints) its current state over its protocol,
    all at once; each answer bounded by ``timeout`` (default: the device's command timeout)."""
    from plugnproduce.executor.links import query_state

    async def one(device: DeviceDescription) -> str:
        try:
            state = await query_state(device, timeout or device.command_timeout)
        except PlugNProduceError as exc:
            raise StateNotReported(f"device {device.id} did not report its state ({exc}); to plan from its chart's "
                                   "initial state instead, give --assume-initial") from None
        if state not in {s.id for s in device.states}:
            raise StateNotReported(f"device {device.id} reports state {state!r}, which its device state chart "
                                   f"{Path(device.chart_file).name} does not have")
        return state

    states = await asyncio.gather(*(one(d) for d in devices.devices))
    return {d.id: x for d, x in zip(devices.devices, states, strict=True)}


async def live_cell(cell_or_path: CellArg, knowledge: Knowledge | None = None,
                    discovery_timeout: float = DISCOVERY_SECONDS, interface: str | None = None) -> Cell:
    """The cell with each device in the state it reports: its devices found by discovery (on ``interface``, else
    ``PNP_INTERFACE`` or loopback, and the SSDP port ``PNP_SSDP_PORT`` names) and asked their states. For ``check``,
    ``repair`` and ``explain`` on a live cell."""
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.opcua.spec import chosen_lds
    from plugnproduce.protocols.upnp import network_from_env

    the_cell, k = cell_and_knowledge(cell_or_path, knowledge)
    wanted = [d.id for d in the_cell.devices]
    async with LiveCell(k.taxonomy, network=network_from_env(interface), name=the_cell.name,
                        expected=wanted, lds=chosen_lds()) as live:
        devices = await find_devices(live, wanted, discovery_timeout)
        return the_cell.reported(await reported_states(devices))


def start_run(generated: GeneratedTask, devices: Cell, journal: Path,
              observer: RecordObserver | None = None, prefixes: Mapping[str, str] | None = None,
              preamble: tuple[tuple[str, dict[str, Any]], ...] = (), speed: float | None = None) -> TaskRun:
    """A run of a planned task (:func:`plan_run`) against ``devices`` (a cell whose devices carry their
    real endpoints), journalling into ``journal``; it starts when its ``run()`` is awaited.

    :func:`planned_run` makes every run this way, once the task is planned. ``preamble``: records journalled
    right after ``start`` (a resumed run's, :mod:`.resume`); ``speed``: the speed factor of simulated devices
    (None: real devices).
    """
    from plugnproduce.executor.run import TaskRun

    return TaskRun(generated, devices, journal, observer, prefixes, preamble, speed=speed)


async def _follow_unplugs(live: LiveCell, run: TaskRun) -> None:
    async for change in live.changes():
        if change.kind == "unplug":
            run.device_lost(change.device, "the device left the network (SSDP byebye)")


