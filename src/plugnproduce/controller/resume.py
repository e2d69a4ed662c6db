"""Resume a run that ended by a fault or a stop: read the devices' states, re-plan the rest, continue once confirmed.

One path for both faces: :func:`replan_live` asks each device its state and plans what runs on from there
(:func:`plugnproduce.service.replan`); :func:`continue_run` starts it once confirmed, its journal beginning
with the ``stopped``, ``replan`` and ``continue`` records. ``pnp resume`` finds the devices by discovery
(:func:`resume_run`); the HMI's Resume uses the devices its cell source follows
(:meth:`plugnproduce.controller.ExecutorRunner.resume`).
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.controller.run import (
    DISCOVERY_SECONDS,
    SIMULATED_DISCOVERY_SECONDS,
    _follow_unplugs,
    find_devices,
    reported_states,
    start_run,
)
from plugnproduce.description.model import Cell
from plugnproduce.errors import PlugNProduceError
from plugnproduce.knowledge import Knowledge
from plugnproduce.service import (
    NoWayOn,
    Replan,
    Stopped,
    cell_and_knowledge,
    new_run_id,
    plan_run,
    replan,
    runs_folder,
    stopped_run,
)

if TYPE_CHECKING:
    from plugnproduce.description.goalfile import Goal
    from plugnproduce.executor.report import RunReport
    from plugnproduce.executor.run import RecordObserver, TaskRun
    from plugnproduce.protocols.upnp import SsdpNetwork
    from plugnproduce.sim.cell import SimulatedCell

Confirm = Callable[[Replan], "str | None"]
"""Shown the plan, says who confirmed it (``the operator``, ``--yes``), or None to decline."""


class NoCell(PlugNProduceError):
    """A resume that does not know the run's cell (its journal names no cell file, and none was given)."""


@dataclass(frozen=True)
class Resumed:
    """What a resume did: the plan, and the continuation's report (None: the plan was declined)."""

    replan: Replan
    report: RunReport | None


async def replan_live(stopped: Stopped, cell: Cell, devices: Cell, knowledge: Knowledge,
                      goal: Goal | str | Path | None = None) -> Replan:
    """Ask each of ``devices`` (the cell's devices at their real endpoints) its state; plan what runs on from there."""
    states = await reported_states(devices)
    return replan(stopped, cell.reported(states), knowledge, goal)


async def continue_run(plan: Replan, cell: Cell, devices: Cell, knowledge: Knowledge, confirmed_by: str,
                       journal: Path | None = None, observer: RecordObserver | None = None,
                       speed: float | None = None) -> TaskRun:
    """The continuation of a confirmed plan, ready to run: the devices are asked their states again and must be
    where the plan starts (:class:`NoWayOn` if one moved meanwhile); ``speed``: the speed factor of simulated
    devices (None: real devices)."""
    now = await reported_states(devices)
    moved = [f"{d} was {s}, is {now.get(d)}" for d, s in sorted(plan.states.items()) if now.get(d) != s]
    if moved:
        raise NoWayOn(f"the devices changed while the plan waited for confirmation ({'; '.join(moved)}); "
                      "resume again to plan from where they are now")
    generated = plan_run(plan.task, cell.reported(now), knowledge)
    preamble = (("stopped", plan.stopped.record()), ("replan", plan.record()), ("continue",
                                                                               {"confirmed_by": confirmed_by}))
    path = journal or runs_folder() / f"{new_run_id(plan.task.name)}.jsonl"
    return start_run(generated, Cell(devices.name, devices.devices, cell.file), path, observer, knowledge.prefixes,
                     preamble, speed=speed)


@dataclass(frozen=True)
class SimulatedResume:
    """Resume on simulated devices started where the run left them (the end record's states): ``faults`` as
    ``pnp run --faults``, working on a bin of ``bin_parts`` parts placed by ``bin_seed`` (None: no bin)."""

    faults: str = ""
    bin_parts: int | None = None
    bin_seed: int = 0


async def resume_run(run: str | Path, cell_or_path: Cell | str | Path | None, confirm: Confirm, *,
                     goal: Goal | str | Path | None = None, journal: Path | None = None,
                     observer: RecordObserver | None = None, started: Callable[[TaskRun], None] | None = None,
                     discovery_timeout: float | None = None, knowledge: Knowledge | None = None,
                     simulate: SimulatedResume | None = None) -> Resumed:
    """Resume a stopped run (``pnp resume``) on the devices discovery finds (``PNP_SSDP_PORT``), or with
    ``simulate`` on simulated devices started in the states the run left them in: plan the rest from their
    states, ask ``confirm`` (in a thread, while discovery goes on), and run it."""
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.upnp import network_from_env, private_network

    stopped = stopped_run(run)
    where = cell_or_path if cell_or_path is not None else stopped.cell_file
    if where is None:
        raise NoCell(f"run {stopped.run}: its journal names no cell file; give --cell CELL")
    the_cell, k = cell_and_knowledge(where, knowledge)
    wanted = [d.id for d in the_cell.devices]
    network = private_network() if simulate is not None else network_from_env()
    async with contextlib.AsyncExitStack() as stack:
        speed = None
        if simulate is not None:
            speed = (await stack.enter_async_context(_simulated(the_cell, stopped, simulate, network))).speed
        live = await stack.enter_async_context(LiveCell(k.taxonomy, network=network, name=the_cell.name,
                                                        expected=wanted))
        devices = await find_devices(live, wanted, discovery_timeout or (SIMULATED_DISCOVERY_SECONDS if simulate
                                                                         else DISCOVERY_SECONDS))
        plan = await replan_live(stopped, the_cell, devices, k, goal)
        who = await asyncio.to_thread(confirm, plan)
        if who is None:
            return Resumed(plan, None)
        the_run = await continue_run(plan, the_cell, devices, k, who, journal, observer, speed)
        if started is not None:
            started(the_run)
        follow = asyncio.create_task(_follow_unplugs(live, the_run))
        try:
            return Resumed(plan, await the_run.run())
        finally:
            follow.cancel()


def _simulated(cell: Cell, stopped: Stopped, simulate: SimulatedResume, network: SsdpNetwork) -> SimulatedCell:
    """The cell's devices simulated, each started in the state the stopped run left it in, at its speed factor."""
    from plugnproduce.sim.bin import SimulatedBin
    from plugnproduce.sim.cell import SimulatedCell, parse_faults

    left = {d: s for d, s in stopped.left.items() if any(x.id == d for x in cell.devices)}
    parts = SimulatedBin(simulate.bin_parts, simulate.bin_seed) if simulate.bin_parts is not None else None
    return SimulatedCell(cell.reported(left), network=network, faults=parse_faults(simulate.faults, cell.devices),
                         bin=parts, speed=stopped.speed or 1.0)
