"""The HTTP error boundary: the same one-line messages the CLI gives, with a 4xx status.

Every error response is ``{"detail": "ONE LINE"}``; a request that does not match its
schema also lists each bad field: ``{"detail": "steps[0].command: field required",
"errors": [{"field": "steps[0].command", "reason": "field required"}]}``. Only the project's
own errors are the request's fault; any other exception is a bug of the server: 500, a line
saying so, and the traceback in the server's log.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any, cast

from fastapi import FastAPI, Request, status
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from plugnproduce.controller.interfaces import CellChangeRefused, RunRefused
from plugnproduce.errors import (
    DescriptionError,
    PlugNProduceError,
    QuantityError,
    UnknownName,
    bug_message,
    excerpt,
    tidy,
)
from plugnproduce.hmi.schemas import LOOP_TAG, STEP_TAG
from plugnproduce.service import NotResumable


def field_name(loc: Sequence[int | str]) -> str:
    """``("body", "steps", 0, "params", "speed")`` → ``steps[0].params.speed``."""
    parts = list(loc[1:] if loc and loc[0] in ("body", "query", "path") else loc)
    parts = [p for p in parts if p not in (STEP_TAG, LOOP_TAG)]
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or (str(loc[0]) if loc else "request")


def _reason(error: dict[str, Any]) -> str:
    msg = str(error.get("msg", "invalid"))
    for prefix in ("Value error, ", "Assertion failed, "):
        msg = msg.removeprefix(prefix)
    if error.get("type") == "missing":
        return "field required"
    if error.get("type") == "json_invalid":
        loc = error.get("loc", ())
        at = f" at character {loc[-1]}" if loc and isinstance(loc[-1], int) else ""
        return f"not valid JSON{at}: {error.get('ctx', {}).get('error', msg)}"
    return tidy(msg[:1].lower() + msg[1:])


def _one(status_code: int, detail: str, **extra: Any) -> JSONResponse:
    return JSONResponse({"detail": detail, **extra}, status_code=status_code)


async def _invalid_request(_: Request, exc: Exception) -> JSONResponse:
    raw = cast(RequestValidationError, exc).errors()  # registered for this class only
    errors = [{"field": "body" if e.get("type") == "json_invalid" else excerpt(field_name(e.get("loc", ()))),
               "reason": _reason(e)} for e in raw]
    unique = list({(e["field"], e["reason"]): e for e in errors}.values())
    code = status.HTTP_400_BAD_REQUEST if any(e.get("type") == "json_invalid" for e in raw) \
        else status.HTTP_422_UNPROCESSABLE_CONTENT
    first = unique[0] if unique else {"field": "request", "reason": "invalid"}
    return _one(code, f"{first['field']}: {first['reason']}", errors=unique)


async def _description(_: Request, exc: Exception) -> JSONResponse:
    return _one(status.HTTP_400_BAD_REQUEST, cast(DescriptionError, exc).location_message())


async def _quantity(_: Request, exc: Exception) -> JSONResponse:
    """A value of the request that is no finite quantity: the request's content is wrong, as a NaN number is."""
    return _one(status.HTTP_422_UNPROCESSABLE_CONTENT, cast(QuantityError, exc).location_message())


async def _unknown(_: Request, exc: Exception) -> JSONResponse:
    return _one(status.HTTP_404_NOT_FOUND, f"error: {tidy(str(exc))}")  # the name came in the request


async def _conflict(_: Request, exc: Exception) -> JSONResponse:
    return _one(status.HTTP_409_CONFLICT, f"error: {tidy(str(exc))}")


async def _other(_: Request, exc: Exception) -> JSONResponse:
    return _one(status.HTTP_400_BAD_REQUEST, f"error: {tidy(str(exc))}")


def install(app: FastAPI) -> None:
    """Register the error boundary on ``app`` (the most specific class wins)."""
    app.add_exception_handler(RequestValidationError, _invalid_request)
    app.add_exception_handler(DescriptionError, _description)
    app.add_exception_handler(QuantityError, _quantity)
    app.add_exception_handler(UnknownName, _unknown)
    app.add_exception_handler(RunRefused, _conflict)
    app.add_exception_handler(CellChangeRefused, _conflict)
    app.add_exception_handler(NotResumable, _conflict)
    app.add_exception_handler(PlugNProduceError, _other)
    app.add_middleware(BugBoundary)  # added first: inside the others, so that a 500 has the security headers too


log = logging.getLogger("plugnproduce.hmi")


class BugBoundary:
    """ASGI middleware: an exception that no handler answers is a bug, not the request's fault.

    The answer is 500 with one line saying so, and the traceback goes to the server's log. (Starlette's
    own last resort answers 500 too, but re-raises the exception after, into the server and the tests.)
    """

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = False

        async def sending(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, receive, sending)
        except Exception as exc:
            log.error("bug answering %s %s", scope.get("method"), scope.get("path"), exc_info=exc)
            if started:  # too late for an answer of its own: the server ends the response
                raise
            detail = bug_message(exc, "the server's log")
            await _one(status.HTTP_500_INTERNAL_SERVER_ERROR, detail)(scope, receive, send)
