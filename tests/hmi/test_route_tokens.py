"""Every HTTP route of the HMI, enumerated from the application: who may call it.

A request that changes the cell or a run needs the bearer token from every address; a
request that only reads (or checks a task) is open on loopback and needs the token from any
other address. The tables below classify every route; a new route must be added to one of
them, so a route nobody thought about fails here instead of being served unguarded. The
routes are read from the application's routing table (not its OpenAPI description), so a
route left out of the description is enumerated too.
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Callable, Iterator
from typing import Any

import fastapi.routing
import httpx
import pytest
from fastapi.dependencies.models import Dependant
from starlette.routing import BaseRoute

from plugnproduce.hmi.security import allow_read, require_token
from tests.hmi.conftest import TOKEN, Hmi

CHANGES = {
    ("POST", "/api/cell/devices"),
    ("DELETE", "/api/cell/devices/{device_id}"),
    ("POST", "/api/runs"),
    ("POST", "/api/runs/{run_id}/stop"),
    ("POST", "/api/runs/{run_id}/replan"),  # asks the devices their states: an operator's step towards a resume
    ("POST", "/api/runs/{run_id}/resume"),
}
"""Requests that change the cell or a run: the token always."""

CHECKS = {
    ("POST", "/api/task/validate"),
    ("POST", "/api/task/check"),
    ("POST", "/api/task/repair"),
    ("POST", "/api/task/explain"),
    ("POST", "/api/task/generate"),
    ("POST", "/api/task/export"),
    ("POST", "/api/task/import"),
    ("POST", "/api/goal/plan"),
}
"""Requests sent with a body that change nothing (a task checked, converted): read rules."""

PUBLIC = {("GET", "/"), ("MOUNT", "/static"), ("GET", "/openapi.json"), ("GET", "/docs"),
          ("GET", "/docs/oauth2-redirect"), ("GET", "/redoc")}
"""The page itself, its static files and the API's description: no data of the cell, open to all."""

REMOTE = ("203.0.113.7", 40000)
"""A client address that is not loopback (TEST-NET-3)."""


def _routing_table(hmi: Hmi) -> Iterator[Any]:
    """Every route the application's router matches, those of its included routers with their
    prefix and the router's own dependencies (FastAPI before 0.16x lists them so in ``app.routes``)."""
    each: Callable[[list[BaseRoute]], Iterator[Any]] | None = getattr(fastapi.routing, "iter_route_contexts", None)
    return each(hmi.app.routes) if each is not None else iter(hmi.app.routes)


def _routes(hmi: Hmi) -> dict[tuple[str, str], set[Callable[..., object]]]:
    """Each (method, path) the application serves, with every dependency it declares; a route that is not
    an HTTP endpoint (a mount, a WebSocket) is listed under its kind, as ``("MOUNT", "/static")``."""
    out: dict[tuple[str, str], set[Callable[..., object]]] = {}
    for route in _routing_table(hmi):
        dependant = getattr(route, "dependant", None)
        calls = set(_calls(dependant)) if isinstance(dependant, Dependant) else set()
        kind = type(getattr(route, "original_route", route)).__name__.upper()
        methods: set[str] = getattr(route, "methods", None) or {kind}
        for method in methods - {"HEAD"}:
            out[(method, route.path)] = calls
    return out


def _app_requests(hmi: Hmi) -> set[tuple[str, str]]:
    """Every (method, path) the application serves with the cell's data: all but the public ones."""
    return set(_routes(hmi)) - PUBLIC


def _calls(dependant: Dependant) -> Iterator[Callable[..., object]]:
    for dep in dependant.dependencies:
        if dep.call is not None:
            yield dep.call
        yield from _calls(dep)


def _url(path: str) -> str:
    return re.sub(r"\{[^}]+\}", "x", path) + ("?step=1" if path.endswith("/explain") else "")


def test_every_route_is_classified(hmi: Hmi) -> None:
    served = _app_requests(hmi)
    reads = {(m, p) for m, p in served if m == "GET"}
    unclassified = served - reads - CHANGES - CHECKS
    assert not unclassified, f"classify these routes in CHANGES or CHECKS: {sorted(unclassified)}"
    assert CHANGES | CHECKS <= served, f"routes gone from the application: {sorted((CHANGES | CHECKS) - served)}"
    assert PUBLIC <= set(_routes(hmi)), f"public routes gone: {sorted(PUBLIC - set(_routes(hmi)))}"


def test_the_routing_table_holds_the_routers_and_the_page(hmi: Hmi) -> None:
    """The enumeration itself: it reaches into the included routers and sees a route left out of OpenAPI."""
    routes = _routes(hmi)
    described = {(m.upper(), p) for p, item in hmi.app.openapi()["paths"].items() for m in item}
    assert described < set(routes) and ("GET", "/") in routes and ("GET", "/") not in described
    assert len(routes) > len(CHANGES | CHECKS | PUBLIC) + 10


def test_each_route_declares_its_guard(hmi: Hmi) -> None:
    wrong = []
    for (method, path), calls in sorted(_routes(hmi).items()):
        if (method, path) in PUBLIC:
            continue
        needed = require_token if (method, path) in CHANGES else allow_read
        if needed not in calls:
            wrong.append(f"{method} {path} lacks {needed.__name__}")
    assert not wrong, "; ".join(wrong)


async def _statuses(hmi: Hmi, client_address: tuple[str, int], requests: list[tuple[str, str]],
                    headers: dict[str, str], started: bool = False) -> dict[str, int]:
    """The status of each request; ``started``: with the application's lifespan (its simulated cell) running."""
    transport = httpx.ASGITransport(app=hmi.app, client=client_address)
    out = {}
    async with contextlib.AsyncExitStack() as stack:
        if started:
            await stack.enter_async_context(hmi.app.router.lifespan_context(hmi.app))
        c = await stack.enter_async_context(httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1"))
        for method, path in requests:
            body = {} if method in ("POST", "PUT", "PATCH") else None
            res = await c.request(method, _url(path), json=body, headers=headers)
            out[f"{method} {path}"] = res.status_code
    return out


@pytest.mark.parametrize("headers", [{}, {"Authorization": "Bearer wrong-token-0123456789"},
                                     {"Authorization": f"Basic {TOKEN}"}, {"Authorization": "Bearer "}],
                         ids=["missing", "wrong", "not bearer", "empty"])
async def test_a_change_without_the_token_is_refused_even_on_loopback(hmi: Hmi, headers: dict[str, str]) -> None:
    statuses = await _statuses(hmi, ("127.0.0.1", 50000), sorted(_app_requests(hmi) & CHANGES), headers)
    assert len(statuses) == len(CHANGES)
    assert {r: s for r, s in statuses.items() if s != 401} == {}


async def test_a_change_with_the_token_gets_past_the_guard(hmi: Hmi) -> None:
    statuses = await _statuses(hmi, ("127.0.0.1", 50000), sorted(_app_requests(hmi) & CHANGES),
                               {"Authorization": f"Bearer {TOKEN}"}, started=True)
    assert {r: s for r, s in statuses.items() if s == 401} == {}  # 404/409/422: the request itself was read


@pytest.mark.parametrize("headers", [{}, {"Authorization": "Bearer wrong-token-0123456789"}], ids=["missing", "wrong"])
async def test_a_read_from_another_host_without_the_token_is_refused(hmi: Hmi, headers: dict[str, str]) -> None:
    requests = sorted(_app_requests(hmi))
    statuses = await _statuses(hmi, REMOTE, requests, headers)
    assert len(statuses) == len(requests) > len(CHANGES | CHECKS)
    assert {r: s for r, s in statuses.items() if s != 401} == {}


async def test_a_read_from_another_host_with_the_token_is_answered(hmi: Hmi) -> None:
    statuses = await _statuses(hmi, REMOTE, [("GET", "/api/cell"), ("GET", "/api/processes")],
                               {"Authorization": f"Bearer {TOKEN}"}, started=True)
    assert set(statuses.values()) == {200}
