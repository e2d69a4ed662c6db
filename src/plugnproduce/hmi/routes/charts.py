"""Pictures of device, process and generated task charts (SVG), and the generated SCXML itself."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Depends, Query, Request
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import Response

from plugnproduce.errors import UnknownName
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.pictures import GeneratedCharts, Pictures, steps_of
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.security import allow_read

router = APIRouter(prefix="/api/charts", tags=["charts"], dependencies=[Depends(allow_read)])
SVG: dict[int | str, dict[str, Any]] = {200: {"content": {"image/svg+xml": {}}}}


def _svg(data: bytes) -> Response:
    return Response(data, media_type="image/svg+xml", headers={"Cache-Control": "no-cache"})


@router.get("/device/{device_id}.svg", response_class=Response, responses=SVG, summary="A Device State Chart")
async def device_chart(device_id: str, request: Request, hub: Hub = Depends(hub_of)) -> Response:
    """The Device State Chart of a device in the cell or the catalogue."""
    known = {d.id: d for d in hub.catalogue} | {d.id: d for d in hub.cell.devices}
    if device_id not in known:
        raise UnknownName("device", device_id, known)
    pictures: Pictures = request.app.state.pictures
    return _svg(await run_in_threadpool(pictures.of_device, known[device_id]))


@router.get("/process/{command}.svg", response_class=Response, responses=SVG, summary="A General Process State Chart")
async def process_chart(command: str, request: Request, hub: Hub = Depends(hub_of)) -> Response:
    """The General Process State Chart of a process."""
    process = hub.knowledge.process(command)  # an unknown command: UnknownName, answered 404
    pictures: Pictures = request.app.state.pictures
    return _svg(await run_in_threadpool(pictures.of_file, process.chart_file))


@router.get("/generated/{generation}/{name}.svg", response_class=Response, responses=SVG,
            summary="A generated chart, drawn")
async def generated_picture(generation: str, name: str, request: Request,
                            step: int | None = Query(None, ge=1, description="A task chart's step to draw expanded"),
                            ) -> Response:
    """The picture of a chart ``POST /api/task/generate`` produced; of a task chart, its steps in order,
    each one box with its process and binding, and ``step`` (if given) expanded into its regions."""
    store: GeneratedCharts = request.app.state.generated
    pictures: Pictures = request.app.state.pictures
    return _svg(await run_in_threadpool(pictures.of_chart, store.chart(generation, name), step))


@router.get("/generated/{generation}/{name}/steps", summary="The steps of a generated task chart")
async def generated_steps(generation: str, name: str, request: Request) -> list[dict[str, object]]:
    """Each step a generated task chart runs, in order: its number, process, binding and step chart."""
    store: GeneratedCharts = request.app.state.generated
    steps = await run_in_threadpool(steps_of, store.chart(generation, name))
    return [{"number": s.number, "command": s.command, "binding": dict(s.binding), "chart": s.chart} for s in steps]


@router.get("/generated/{generation}/{name}", response_class=Response,
            responses={200: {"content": {"application/xml": {}}}}, summary="A generated chart (W3C SCXML)")
def generated_scxml(generation: str, name: str, request: Request) -> Response:
    """The SCXML of a chart ``POST /api/task/generate`` produced."""
    store: GeneratedCharts = request.app.state.generated
    chart = store.chart(generation, name)
    return Response(chart.data, media_type="application/xml",
                    headers={"Content-Disposition": f'attachment; filename="{chart.name}"'})
