"""Fixtures for the HMI: the application over the simulated bin-picking cell (followed by discovery,
run by the executor), an in-process HTTP client, a real uvicorn server on a free loopback port,
and headless Chromium driven by Playwright."""

from __future__ import annotations

import socket
import threading
from collections.abc import AsyncIterator, Iterator
from dataclasses import dataclass
from pathlib import Path

import httpx
import pytest
import uvicorn
from fastapi import FastAPI

from plugnproduce import service
from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app
from plugnproduce.sim.bin import SimulatedBin

TOKEN = "test-token-0123456789abcdef"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
SCREENSHOTS = Path(__file__).resolve().parents[2] / "artifacts" / "screenshots"
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]

@dataclass
class Hmi:
    """An HMI application and what it was built over."""

    app: FastAPI
    source: SimulatedCellSource
    runner: ExecutorRunner


def make_hmi(tmp_path: Path, cell: str = "bin-picking", faults: str = "", bin: SimulatedBin | None = None) -> Hmi:  # noqa: A002
    """The HMI over a built-in cell, simulated (with ``faults``, working on ``bin``) once the app starts;
    runs journalled under ``tmp_path``."""
    source = SimulatedCellSource(service.cell(service.builtin("cells", f"{cell}.yaml")), service.catalogue(),
                                 faults=faults, bin=bin)
    runner = ExecutorRunner(source, tmp_path / "runs")
    return Hmi(create_app(source, runner, TOKEN), source, runner)


@pytest.fixture()
def hmi(tmp_path: Path) -> Hmi:
    return make_hmi(tmp_path)


@pytest.fixture()
async def client(hmi: Hmi) -> AsyncIterator[httpx.AsyncClient]:
    """An HTTP client calling the application in process, as a client on loopback."""
    transport = httpx.ASGITransport(app=hmi.app, client=("127.0.0.1", 50000))
    async with hmi.app.router.lifespan_context(hmi.app):
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as c:
            yield c


@dataclass
class Served:
    """A running server: its base URL and the HMI behind it."""

    url: str
    hmi: Hmi


@pytest.fixture()
def served(tmp_path: Path, request: pytest.FixtureRequest) -> Iterator[Served]:
    """The HMI served by uvicorn on a free loopback port (listening before the thread starts: no waiting).

    Parametrize it indirectly with a ``--faults`` spec to inject faults into the simulated devices,
    with a :class:`SimulatedBin` for the simulated devices to work on, or with both as a pair.
    """
    param = getattr(request, "param", "")
    if isinstance(param, tuple):  # both: faults injected into devices working on a bin
        hmi = make_hmi(tmp_path, faults=param[0], bin=param[1])
    else:
        hmi = make_hmi(tmp_path, faults=param, bin=None) if isinstance(param, str) else make_hmi(tmp_path, bin=param)
    sock = socket.create_server(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    config = uvicorn.Config(hmi.app, log_level="warning", lifespan="on", ws="none", timeout_graceful_shutdown=1)
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, name="hmi-server", daemon=True)
    thread.start()
    try:
        yield Served(f"http://127.0.0.1:{port}", hmi)
    finally:
        hmi.app.state.hub.close_streams()
        server.should_exit = True
        thread.join(10)
        sock.close()


@pytest.fixture(scope="module")
def browser() -> Iterator[object]:
    """Headless Chromium (the system's), shared by the browser tests of one module."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            yield b
        finally:
            b.close()


@pytest.fixture()
def page(browser: object, served: Served) -> Iterator[object]:
    """A fresh page on the served HMI, opened with the token in its address, ready when the cell is shown."""
    from playwright.sync_api import Browser

    assert isinstance(browser, Browser)
    context = browser.new_context(viewport={"width": 1360, "height": 1000}, accept_downloads=True)
    pg = context.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(f"{served.url}/#token={TOKEN}")
    pg.wait_for_selector("body[data-ready='true']")
    pg.wait_for_selector("#devices tbody tr")
    try:
        yield pg
    finally:
        context.close()
    assert not errors, errors


def screenshot(page: object, name: str) -> Path:
    """Save the page as ``artifacts/screenshots/NAME.png``."""
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    path = SCREENSHOTS / f"{name}.png"
    page.screenshot(path=str(path), full_page=True)  # type: ignore[attr-defined]
    return path
