"""The FastAPI application: the HTTP API (OpenAPI at ``/openapi.json``) and the page, in one process."""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib import resources
from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles
from starlette.middleware.trustedhost import TrustedHostMiddleware

from plugnproduce import service
from plugnproduce.controller.interfaces import CellSource, Runner
from plugnproduce.hmi import errors
from plugnproduce.hmi.hub import Hub
from plugnproduce.hmi.pictures import GeneratedCharts, Pictures
from plugnproduce.hmi.routes import cell, charts, goal, runs, sources, task, teach
from plugnproduce.hmi.security import BodyLimit, SecurityHeaders
from plugnproduce.hmi.work import WAITING, WORK_MEMORY, WORK_SECONDS, WORKERS, Work, WorkLimits
from plugnproduce.service import MAX_BYTES, DeviceDescription, Knowledge

DESCRIPTION = f"""\
The Generic HMI of a Plug'n'Produce cell: the live cell, the process commands it offers,
tasks checked, repaired, explained and turned into SCXML, and runs watched live.

Requests that change the cell or a run need `Authorization: Bearer TOKEN` (the token
`pnp serve` prints); the others are open to clients on this machine. Errors are
`{{"detail": "one line"}}` with the messages the `pnp` command line gives.

Checking, validating, repairing, explaining and generating a task, importing a task file and
explaining a process command run in worker processes, each under a budget: {WORK_SECONDS:g} s (504,
`"the check took longer than {WORK_SECONDS:g} s; try a shorter task"`) and {WORK_MEMORY // 1024**2} MiB of
memory (413). A request whose client disconnects is stopped at once. {WORKERS} run at a time and
{WAITING} more may wait; a request beyond that is refused with 503 and `Retry-After`. The cell, the commands,
the processes and the event stream are answered meanwhile.
"""


def static_folder() -> Path:
    """The page's files, shipped inside the package."""
    return Path(str(resources.files("plugnproduce.hmi") / "static"))


def create_app(
    source: CellSource,
    runner: Runner,
    token: str,
    catalogue: list[DeviceDescription] | None = None,
    allowed_hosts: list[str] | None = None,
    knowledge: Knowledge | None = None,
    limits: WorkLimits | None = None,
) -> FastAPI:
    """The HMI application over a cell source and a runner.

    ``token`` guards every request that changes something; ``catalogue`` is what repairs may add
    (default: the devices of ``knowledge``, itself by default the built-in library);
    ``allowed_hosts`` (e.g. ``["127.0.0.1", "localhost"]``) refuses
    requests for any other ``Host``, which stops DNS-rebinding pages from reading the API;
    ``limits`` bound the expensive requests (time budget, workers, waiting requests, memory; see
    :mod:`plugnproduce.hmi.work`).
    """
    knowledge = knowledge or service.knowledge()
    service.make_all_classes()  # before the server's threads use them (plugnproduce.deferred)
    devices = catalogue if catalogue is not None else service.catalogue(knowledge=knowledge)
    hub = Hub(source, runner, devices, knowledge)
    work = Work(limits or WorkLimits(), hub.knowledge, devices)

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        await hub.start()
        work.start()  # in the background: the first expensive request waits for the workers
        try:
            yield
        finally:
            await work.stop()
            await hub.stop()

    app = FastAPI(title="Plug'n'Produce HMI", description=DESCRIPTION, version="1", lifespan=lifespan)
    app.state.hub = hub
    app.state.work = work
    app.state.token = token
    app.state.pictures = Pictures()
    app.state.generated = GeneratedCharts()
    errors.install(app)
    for router in (cell.router, task.router, goal.router, charts.router, runs.router, sources.router,
                   teach.router):
        app.include_router(router)
    folder = static_folder()
    app.mount("/static", StaticFiles(directory=folder), name="static")

    @app.get("/", include_in_schema=False)
    def page() -> FileResponse:
        return FileResponse(folder / "index.html", headers={"Cache-Control": "no-cache"})

    app.add_middleware(SecurityHeaders)
    app.add_middleware(BodyLimit, limit=MAX_BYTES)
    if allowed_hosts:
        app.add_middleware(TrustedHostMiddleware, allowed_hosts=allowed_hosts)
    return app


def stop_requests(app: FastAPI) -> None:
    """Stop every expensive request of an HMI application still being worked on (its server is stopping):
    each ends at once with 503."""
    work: Work = app.state.work
    work.cancel_all()
