"""A task from the editor: validate, check, repair, explain a step, generate its code; YAML in and out.

None of these change anything, so they are open on loopback like every other read.
Implausible is a result (``"plausible": false``), never an error status.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends, HTTPException, Query, Request, status
from fastapi.responses import PlainTextResponse

from plugnproduce import service
from plugnproduce.hmi import taskfiles
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.pictures import GeneratedCharts
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.schemas import TaskIn
from plugnproduce.hmi.security import allow_read
from plugnproduce.hmi.views import editor_rows, task_json

router = APIRouter(prefix="/api/task", tags=["task"], dependencies=[Depends(allow_read)])


def _rows(problems: list[dict[str, Any]], task: TaskIn) -> list[dict[str, Any]]:
    """Add to each problem the editor row of its step (steps repeat: step 5 of 2 rows is row 0, round 3;
    a loop's later iterations are its round 2) and the path it lies on (``branch NoPartFound at step 2``)."""
    model = task.to_task()
    rows = editor_rows(model)
    for p in problems:
        step = p.get("step")
        if isinstance(step, int) and step in rows:
            p["row"], p["round"] = rows[step]
            p["path"] = model.path(step)
    return problems


@router.post("/validate", summary="Validate the task like a task file: types, ranges, known commands")
def validate(task: TaskIn, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Schema, SHACL shapes and structure, as ``pnp validate`` does; each problem names its editor field."""
    return taskfiles.validate_task(task, hub.knowledge)


@router.post("/check", summary="Is the task plausible in the cell as it is now?")
def check(task: TaskIn, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """``service.check``: per step its bindings and device states, and every problem at its step."""
    result = service.check(task.to_task(), hub.planning_cell, hub.knowledge).to_json()
    problems = result["problems"]
    if not isinstance(problems, list):
        raise TypeError(f"a check result's problems are a list; found {type(problems).__name__}")
    result["problems"] = _rows(problems, task)
    return result


@router.post("/repair", summary="Ranked minimal repairs of an implausible task")
def repair(task: TaskIn, top: int = Query(3, ge=1, le=20), hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """``service.assessed_repairs`` with the catalogue: each repair's edits, cost, side effects (ranked by them)
    and resulting task (ready to apply)."""
    model, cell = task.to_task(), hub.planning_cell
    result = service.check(model, cell, hub.knowledge)
    repairs = [] if result.plausible else service.assessed_repairs(model, cell, hub.catalogue, top, hub.knowledge)
    return {
        "plausible": result.plausible,
        "problems": _rows([p.to_json() for p in result.problems], task),
        "repairs": [{**r.to_json(), "task": task_json(r.repair.task)} for r in repairs],
    }


@router.post("/explain", summary="Why a step is (not) plausible")
def explain(task: TaskIn, step: int = Query(..., ge=1, description="The step, from 1 in the repeated order"),
            hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """``service.explain_step`` and ``service.explain_plausible``: each device's state before the step, where it
    came from, what the step needs, the derivation tree and the states that would make the step plausible."""
    model = task.to_task()
    why = service.explain_plausible(model, hub.planning_cell, step, hub.knowledge)
    return {**service.explain_step(model, hub.planning_cell, step, hub.knowledge).to_json(), **why.to_json()}


@router.post("/generate", summary="Generate the SCXML charts of a plausible task")
def generate(task: TaskIn, request: Request, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Specific process charts, the Task State Chart and the closed-world chart, each as SCXML and SVG.

    ``service.generation``: an implausible task is a result (its problems, no charts), not an error.
    """
    result = service.generation(task.to_task(), hub.planning_cell, knowledge=hub.knowledge)
    out: dict[str, Any] = {"plausible": result.check.plausible,
                           "problems": _rows([p.to_json() for p in result.check.problems], task),
                           "generation": None, "charts": []}
    if result.charts:
        store: GeneratedCharts = request.app.state.generated
        gen = store.add(result.charts)
        base = f"/api/charts/generated/{gen}"
        out["generation"] = gen
        out["charts"] = [{"name": c.name, "kind": c.kind, "scxml": f"{base}/{c.name}", "svg": f"{base}/{c.name}.svg"}
                         for c in result.charts]
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
    return task_json(taskfiles.import_yaml(data, filename))
