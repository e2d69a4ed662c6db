"""Runs (start, stop, status, journal) through the :class:`~plugnproduce.controller.interfaces.Runner`, and the
server-sent event stream every page listens to: cell changes, device states and run progress."""

from __future__ import annotations

import asyncio
import json
from collections.abc import AsyncIterator
from typing import Any

from fastapi import APIRouter, Depends, Query, status
from fastapi.responses import PlainTextResponse, Response, StreamingResponse

from plugnproduce.hmi.hub import Hub, format_event
from plugnproduce.hmi.routes import hub_of
from plugnproduce.hmi.schemas import ResumeIn, RunIn
from plugnproduce.hmi.security import allow_read, require_token
from plugnproduce.hmi.views import run_json

router = APIRouter(tags=["runs"])
read = [Depends(allow_read)]
change = [Depends(require_token)]
PING_SECONDS = 15.0


def _view(hub: Hub, run_id: str) -> dict[str, Any]:
    return run_json(run_id, hub.runner.journal(run_id), hub.runner.active() == run_id)


@router.get("/api/runs", dependencies=read, summary="Every run since the server started, and the active one")
def list_runs(hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """The runs (oldest first) with their status."""
    runs = []
    for run_id in hub.runner.runs():
        view = _view(hub, run_id)
        runs.append({k: view[k] for k in ("run", "task", "status", "speed")})
    return {"active": hub.runner.active(), "runs": runs}


@router.post("/api/runs", dependencies=change, status_code=status.HTTP_202_ACCEPTED, summary="Start a run")
async def start_run(body: RunIn, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Start running a task in the cell as it is now (409 when a run is active or the task cannot run)."""
    run_id = await hub.start_run(body.task.to_task())
    return _view(hub, run_id)


@router.get("/api/runs/{run_id}", dependencies=read, summary="A run's status, current step and device states")
def get_run(run_id: str, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """What the run's journal says so far, with the fault report when it failed."""
    return _view(hub, run_id)


@router.post("/api/runs/{run_id}/stop", dependencies=change, summary="Stop a run")
async def stop_run(run_id: str, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Stop the run; every device stays in a safe state."""
    await hub.runner.stop(run_id)
    return _view(hub, run_id)


@router.post("/api/runs/{run_id}/replan", dependencies=change, summary="Re-plan a failed or stopped run")
async def replan_run(run_id: str, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Ask each device its state and plan the rest of the run's task from there: the plan (its task file,
    steps and repairs) and the states, for the operator to confirm (409 when nothing plausible goes on)."""
    return await hub.replan_run(run_id)


@router.post("/api/runs/{run_id}/resume", dependencies=change, status_code=status.HTTP_202_ACCEPTED,
             summary="Resume a failed or stopped run")
async def resume_run(run_id: str, body: ResumeIn, hub: Hub = Depends(hub_of)) -> dict[str, Any]:
    """Re-plan the run and start the plan; its journal begins with the stop, the re-plan and the confirmation.
    With ``states`` (the plan's, as shown), 409 when the devices have changed since."""
    new_id = await hub.resume_run(run_id, body.states)
    return _view(hub, new_id)


@router.get("/api/runs/{run_id}/journal", dependencies=read, response_model=None,
            summary="A run's journal records (JSON, or JSON lines with ?format=jsonl)")
def get_journal(run_id: str, format: str = Query("json", pattern="^(json|jsonl)$"),
                hub: Hub = Depends(hub_of)) -> Response | list[dict[str, Any]]:
    """The journal as the executor wrote it."""
    records = hub.runner.journal(run_id)
    if format == "jsonl":
        text = "".join(json.dumps(r, sort_keys=True, default=str) + "\n" for r in records)
        return PlainTextResponse(text, media_type="application/jsonl",
                                 headers={"Content-Disposition": f'attachment; filename="{run_id}.jsonl"'})
    return records


async def _stream(hub: Hub) -> AsyncIterator[str]:
    queue = hub.subscribe()
    try:
        yield "retry: 1000\n\n"
        yield format_event("cell", {"change": None, **hub.cell_view()})
        active = hub.runner.active()
        if active is not None:
            yield format_event("run-snapshot", _view(hub, active))
        while True:
            try:
                item = await asyncio.wait_for(queue.get(), PING_SECONDS)
            except TimeoutError:
                yield ": ping\n\n"
                continue
            if item is None:
                return
            yield item
    finally:
        hub.unsubscribe(queue)


@router.get("/events", dependencies=read, response_class=StreamingResponse,
            responses={200: {"content": {"text/event-stream": {}}}},
            summary="Server-sent events: cell, device-state, run, run-snapshot")
async def events(hub: Hub = Depends(hub_of)) -> StreamingResponse:
    """``cell`` (devices and re-inferred commands, at once and on every plug/unplug), ``device-state``,
    ``run`` (each journal record of a run, with a human line) and ``run-snapshot`` (on connect, if a run is active)."""
    return StreamingResponse(_stream(hub), media_type="text/event-stream",
                             headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})
