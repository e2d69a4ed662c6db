"""The HTTP API's routers, one per part of the page: cell, task, charts, runs and the event stream."""

from __future__ import annotations

from fastapi import Request

from plugnproduce.hmi.hub import Hub


def hub_of(request: Request) -> Hub:
    """Dependency: the application's hub."""
    hub: Hub = request.app.state.hub
    return hub
