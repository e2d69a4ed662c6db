"""Who may do what: a bearer token for every request that changes the cell or runs a task.

Requests that only read (the cell, the processes, checking or explaining a task) are open
to clients on the loopback interface; from any other address they need the token too.
Requests that change something (plug, unplug, start or stop a run) always need it. The
page's own responses carry a strict Content-Security-Policy.
"""

from __future__ import annotations

import ipaddress
import json
import secrets
from pathlib import Path

from fastapi import HTTPException, Request, status
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from plugnproduce.errors import DescriptionError

TOKEN_HELP = "send the token 'pnp serve' printed as the header 'Authorization: Bearer TOKEN'"


def new_token() -> str:
    """A fresh random token."""
    return secrets.token_urlsafe(24)


def read_token(path: str | Path) -> str:
    """The token kept in a file (its first line); DescriptionError if it is missing or empty."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise DescriptionError(f"cannot read the token file: {exc.strerror or exc}", p) from exc
    except UnicodeDecodeError as exc:
        raise DescriptionError(f"the token file is not UTF-8 text (byte {exc.start + 1})", p) from exc
    token = text.strip().splitlines()[0].strip() if text.strip() else ""
    if len(token) < 16:
        raise DescriptionError(f"the token must be at least 16 characters on the first line; found {len(token)}", p, 1)
    return token


def is_loopback(host: str | None) -> bool:
    """Whether a client address is on the loopback interface (an IPv6 address may carry its zone, ``::1%lo``)."""
    if not host:
        return False
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


def _bearer(request: Request) -> str | None:
    scheme, _, value = request.headers.get("authorization", "").partition(" ")
    return value.strip() if scheme.lower() == "bearer" and value.strip() else None


def _refuse(reason: str) -> HTTPException:
    return HTTPException(status.HTTP_401_UNAUTHORIZED, f"{reason}; {TOKEN_HELP}",
                         headers={"WWW-Authenticate": 'Bearer realm="pnp"'})


def require_token(request: Request) -> None:
    """Dependency of every request that changes something: the bearer token must match."""
    token: str = request.app.state.token
    given = _bearer(request)
    if given is None:
        raise _refuse("this request changes the cell or a run and needs the bearer token")
    if not secrets.compare_digest(given.encode(), token.encode()):
        raise _refuse("wrong bearer token")


def allow_read(request: Request) -> None:
    """Dependency of every request that only reads: open on loopback, else the token (header or ``?token=``)."""
    if is_loopback(request.client.host if request.client else None):
        return
    given = _bearer(request) or request.query_params.get("token")
    if given is None or not secrets.compare_digest(given.encode(), str(request.app.state.token).encode()):
        raise _refuse("requests from other hosts than this one need the bearer token")


PAGE_POLICY = (
    "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; connect-src 'self'; "
    "object-src 'none'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'"
)


class SecurityHeaders:
    """ASGI middleware: no sniffing, no referrer, and the page's Content-Security-Policy (not on /docs)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        path: str = scope["path"]
        strict = not (path.startswith("/docs") or path.startswith("/redoc"))

        async def with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = list(message.get("headers", []))
                headers.append((b"x-content-type-options", b"nosniff"))
                headers.append((b"referrer-policy", b"no-referrer"))
                if strict:
                    headers.append((b"content-security-policy", PAGE_POLICY.encode()))
                message["headers"] = headers
            await send(message)

        await self.app(scope, receive, with_headers)


class BodyLimit:
    """ASGI middleware: a request body larger than ``limit`` bytes is refused (413) as it streams in.

    The declared ``Content-Length`` is checked first; a chunked body, which declares none, is
    counted as it arrives, so no request holds more than ``limit`` bytes of the server's memory.
    """

    def __init__(self, app: ASGIApp, limit: int) -> None:
        self.app = app
        self.limit = limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length", b"")
        if declared.isdigit() and int(declared) > self.limit:
            await _too_large(send, self.limit)
            return
        seen = 0

        async def counted() -> Message:
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > self.limit:
                    raise HTTPException(status.HTTP_413_CONTENT_TOO_LARGE, _too_large_text(self.limit))
            return message

        await self.app(scope, counted, send)


def _too_large_text(limit: int) -> str:
    return f"the request body is larger than the {limit} bytes accepted"


async def _too_large(send: Send, limit: int) -> None:
    body = json.dumps({"detail": _too_large_text(limit)}).encode()
    await send({"type": "http.response.start", "status": 413,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})
