"""The HTTP API's routers, one per part of the page: cell, task, charts, runs and the event stream."""

from __future__ import annotations

from fastapi import HTTPException, Request, status

from plugnproduce.hmi.hub import Hub, reasoner_available


def hub_of(request: Request) -> Hub:
    """Dependency: the application's hub."""
    hub: Hub = request.app.state.hub
    return hub


def require_reasoner() -> None:
    """Dependency of the reasoner's use cases: 501 while ``service.capabilities`` and friends are missing."""
    if not reasoner_available():
        raise HTTPException(status.HTTP_501_NOT_IMPLEMENTED,
                            "error: the reasoner is not installed (plugnproduce.service has no capabilities/check)")
