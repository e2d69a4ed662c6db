"""Teach-in from the page: which devices of the cell report which values, and one value read from a device.

The step dialog shows "Teach" beside a parameter whose quantity a device of the cell reports; the value is
read by the device's state query (:func:`plugnproduce.controller.read_taught`) and held to its contracts.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends

from plugnproduce import controller, service
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.security import allow_read

router = APIRouter(prefix="/api", tags=["teach"], dependencies=[Depends(allow_read)])


@router.get("/teach", summary="The values each device of the cell reports with its state (teach-in)")
def reports(hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """``reports``: per device, the quantities it reports (``TargetPose``), for the dialog's Teach buttons."""
    return {"reports": {d.id: service.reported_quantities(d) for d in hub.cell.devices
                        if service.reported_quantities(d)}}


@router.get("/teach/{device}/{quantity}", summary="Read a value a device reports, held to its contracts")
async def teach(device: str, quantity: str, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """The value as the device reports it now, the state it reported with it, the contracts it was held to and
    why any refuses it (``accepted`` false); 404 for a device or quantity the cell does not have."""
    taught = await controller.read_taught(hub.cell.device(device), quantity)
    return taught.to_json()
