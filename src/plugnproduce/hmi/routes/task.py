"""A task from the editor: validate, check, repair, explain a step, generate its code; YAML in and out.

None of these change anything, so they are open on loopback like every other read.
Implausible is a result (``"plausible": false``), never an error status. All but export run in a
worker process under a time budget and stop when their client goes away (:mod:`plugnproduce.hmi.work`).
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends, HTTPException, Query, Request, status
from fastapi.responses import PlainTextResponse

from plugnproduce.hmi import jobs, taskfiles
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.pictures import GeneratedCharts
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.schemas import TaskIn
from plugnproduce.hmi.security import allow_read
from plugnproduce.hmi.work import Work, work_of

router = APIRouter(prefix="/api/task", tags=["task"], dependencies=[Depends(allow_read)])


@router.post("/validate", summary="Validate the task like a task file: types, ranges, known commands")
async def validate(task: TaskIn, request: Request, work: Work = Depends(work_of)) -> dict[str, Any]:
    """Schema, SHACL shapes and structure, as ``pnp validate`` does; each problem names its editor field."""
    return await work.run(request, "the validation", jobs.validate, task)


@router.post("/check", summary="Is the task plausible in the cell as it is now?")
async def check(task: TaskIn, request: Request, hub: Hub = Depends(hub_of),
                work: Work = Depends(work_of)) -> dict[str, Any]:
    """``service.check``: per step its bindings and device states, and every problem at its step."""
    return await work.run(request, "the check", jobs.check, task, hub.planning_cell)


@router.post("/repair", summary="Ranked minimal repairs of an implausible task")
async def repair(task: TaskIn, request: Request, top: int = Query(3, ge=1, le=20), hub: Hub = Depends(hub_of),
                 work: Work = Depends(work_of)) -> dict[str, Any]:
    """``service.assessed_repairs`` with the catalogue: each repair's edits, cost, side effects (ranked by them)
    and resulting task (ready to apply)."""
    return await work.run(request, "the repair", jobs.repair, task, hub.planning_cell, top)


@router.post("/explain", summary="Why a step is (not) plausible")
async def explain(task: TaskIn, request: Request,
                  step: int = Query(..., ge=1, description="The step, from 1 in the repeated order"),
                  hub: Hub = Depends(hub_of), work: Work = Depends(work_of)) -> dict[str, Any]:
    """``service.explain_step`` and ``service.explain_plausible``: each device's state before the step, where it
    came from, what the step needs, the derivation tree and the states that would make the step plausible."""
    return await work.run(request, "the explanation", jobs.explain, task, hub.planning_cell, step)


@router.post("/generate", summary="Generate the SCXML charts of a plausible task, once its program is proved")
async def generate(task: TaskIn, request: Request, hub: Hub = Depends(hub_of),
                   work: Work = Depends(work_of)) -> dict[str, Any]:
    """Specific process charts, the Task State Chart and the closed-world chart, each as SCXML and SVG.

    ``service.generation``: an implausible task is a result (its problems, no charts), not an error; so is a
    program verification does not prove (``verification``: refuted with its shortest trace, or inconclusive),
    for which no charts are made, as ``pnp generate`` writes none.
    """
    out, charts = await work.run(request, "the code generation", jobs.generate, task, hub.planning_cell)
    out = {**out, "generation": None, "charts": []}
    if charts:
        store: GeneratedCharts = request.app.state.generated
        gen = store.add(charts)
        base = f"/api/charts/generated/{gen}"
        out["generation"] = gen
        out["charts"] = [{"name": c.name, "kind": c.kind, "scxml": f"{base}/{c.name}", "svg": f"{base}/{c.name}.svg"}
                         for c in charts]
    return out


@router.post("/export", response_class=PlainTextResponse, summary="The task as a YAML task description",
             responses={200: {"content": {"application/yaml": {}}}})
def export(task: TaskIn) -> PlainTextResponse:
    """YAML as the task file format writes it (one round of the steps, and ``repeat``)."""
    text = taskfiles.export_yaml(task.to_task())
    filename = "".join(c if c.isalnum() or c in "-_." else "_" for c in task.name) or "task"
    return PlainTextResponse(text, media_type="application/yaml",
                             headers={"Content-Disposition": f'attachment; filename="{filename}.yaml"'})


YAML_TYPES = ("application/yaml", "application/x-yaml", "text/yaml", "text/x-yaml")
YAML_BODY = {"requestBody": {"required": True, "description": "A YAML task description",
                             "content": {"application/yaml": {"schema": {"type": "string"}}}}}


@router.post("/import", summary="Read a YAML task description into the editor's JSON", openapi_extra=YAML_BODY)
async def import_(
    request: Request,
    filename: str = Query("task.yaml", max_length=200, description="The file's name, for error messages"),
    work: Work = Depends(work_of),
) -> dict[str, Any]:
    """Parse YAML with the task file's hardened reader; errors are ``FILE:LINE: message``.

    The body must be sent as YAML (``application/yaml``): a type a cross-site form may send
    without asking (``text/plain``, forms) is refused, so no other page can post here.
    """
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind not in YAML_TYPES:
        raise HTTPException(status.HTTP_415_UNSUPPORTED_MEDIA_TYPE,
                            f"{filename}: send the task as application/yaml; found {kind or 'no content type'}")
    data = await request.body()
    return await work.run(request, "reading the task file", jobs.import_yaml, data, filename)
