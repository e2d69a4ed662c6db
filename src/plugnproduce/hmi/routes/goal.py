"""The Goal view: a goal (YAML, as ``pnp plan`` reads it) planned in the cell as it is now.

Like the task's requests it changes nothing and runs in a worker process under the work budget.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends, HTTPException, Query, Request, status

from plugnproduce.hmi import jobs
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.routes.task import YAML_BODY, YAML_TYPES
from plugnproduce.hmi.security import allow_read
from plugnproduce.hmi.work import Work, work_of

router = APIRouter(prefix="/api/goal", tags=["goal"], dependencies=[Depends(allow_read)])


@router.post("/plan", summary="Plan a task from a goal in the cell as it is now", openapi_extra=YAML_BODY)
async def plan(
    request: Request,
    filename: str = Query("goal.yaml", max_length=200, description="The goal's name, for error messages"),
    hub: Hub = Depends(hub_of),
    work: Work = Depends(work_of),
) -> dict[str, Any]:
    """``service.plan`` from the devices' states: ``reachable`` with the plan's steps, its task (the editor's
    JSON and the task file), the check's verdict and the estimated ``cycle_time`` (as ``pnp check --json`` gives
    it); or ``reasons`` and the cheapest ``purchase``. A goal file
    that cannot be read is 400 with ``FILE:LINE: message``. The body is YAML (``application/yaml``)."""
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind not in YAML_TYPES:
        raise HTTPException(status.HTTP_415_UNSUPPORTED_MEDIA_TYPE,
                            f"{filename}: send the goal as application/yaml; found {kind or 'no content type'}")
    data = await request.body()
    return await work.run(request, "the plan", jobs.plan_goal, data, filename, hub.planning_cell)
