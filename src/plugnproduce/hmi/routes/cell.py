"""The cell, its catalogue, plug and unplug; the processes and the process commands the cell offers."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends, HTTPException, Request, status

from plugnproduce.controller.interfaces import PluggableCellSource
from plugnproduce.hmi import jobs
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.schemas import PlugIn
from plugnproduce.hmi.security import allow_read, require_token
from plugnproduce.hmi.views import device_json, process_json
from plugnproduce.hmi.work import Work, work_of

router = APIRouter(prefix="/api", tags=["cell"])
read = [Depends(allow_read)]
change = [Depends(require_token)]


@router.get("/cell", dependencies=read, summary="The live cell: devices with class, skills, protocol, state")
def get_cell(hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """The cell as it is now, each device with its current chart state, and whether it can be changed here."""
    view = hub.cell_view()
    return {**view["cell"], "pluggable": isinstance(hub.source, PluggableCellSource)}


@router.get("/catalogue", dependencies=read, summary="Devices that can be plugged in or added by a repair")
def get_catalogue(hub: Hub = Depends(hub_of)) -> list[dict[str, Any]]:
    """The catalogue: every known device, and whether it is in the cell now."""
    taxonomy = hub.knowledge.taxonomy
    present = {d.id for d in hub.cell.devices}
    source = hub.source
    devices = source.catalogue() if isinstance(source, PluggableCellSource) else hub.catalogue
    return [{**device_json(d, taxonomy), "in_cell": d.id in present} for d in devices]


def _pluggable(hub: Hub) -> PluggableCellSource:
    if not isinstance(hub.source, PluggableCellSource):
        raise HTTPException(status.HTTP_409_CONFLICT,
                            "error: this cell follows discovery; plug or unplug the device itself")
    return hub.source


@router.post("/cell/devices", dependencies=change, summary="Plug a catalogue device in")
async def plug(body: PlugIn, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Plug a catalogue device into the cell; every page hears of it and of the re-inferred commands."""
    await _pluggable(hub).plug(body.device)
    return hub.cell_view()


@router.delete("/cell/devices/{device_id}", dependencies=change, summary="Unplug a device")
async def unplug(device_id: str, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Unplug a device from the cell."""
    await _pluggable(hub).unplug(device_id)
    return hub.cell_view()


@router.get("/commands", dependencies=read,
            summary="Offered process commands with bindings; the others with reasons")
def get_commands(hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """``service.capabilities`` of the cell as it is now."""
    return hub.commands()


@router.get("/commands/{command}/explanation", dependencies=read,
            summary="Why a process command is (not) offered")
async def explain_command(command: str, request: Request, hub: Hub = Depends(hub_of),
                          work: Work = Depends(work_of)) -> dict[str, Any]:
    """``service.explain_process`` and ``service.explain_offered``: the bindings or the reasons, the derivation
    tree (rules, ontology axioms, chart states, each with its line) and the counterfactuals the reasoner
    confirms (catalogue devices to plug in or swap in; for an offered command, the devices it rests on).
    Runs in a worker under the time budget, like a check."""
    return await work.run(request, "the explanation", jobs.explain_command, hub.cell, command,
                          advice="try again with fewer devices in the cell")


@router.get("/processes", dependencies=read, summary="Every known process with its roles and parameters")
def get_processes(hub: Hub = Depends(hub_of)) -> list[dict[str, Any]]:
    """The processes: command, label, roles (skill, start and end state) and parameters for the dialogs."""
    k = hub.knowledge
    return [process_json(p, k.taxonomy) for p in k.processes]


@router.get("/processes/{command}", dependencies=read, summary="One process with its roles and parameters")
def get_process(command: str, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """One process by its command name."""
    k = hub.knowledge
    return process_json(k.process(command), k.taxonomy)  # an unknown command: UnknownName, answered 404
