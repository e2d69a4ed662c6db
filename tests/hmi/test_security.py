"""The HMI's guards one by one: the token file, the token itself, who counts as loopback,
the bearer header, the answer a refused client gets, the page's headers and the body limit."""

from __future__ import annotations

import locale
from collections.abc import AsyncIterator, Iterator
from pathlib import Path

import httpx
import pytest
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from plugnproduce.errors import DescriptionError
from plugnproduce.hmi.security import BodyLimit, SecurityHeaders, is_loopback, new_token, read_token
from tests.hmi.conftest import TOKEN, Hmi

# --- the token file ------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "token"), [
    ("a" * 16, "a" * 16),
    ("  \n  secret-token-0123456789  \nsecond line\n", "secret-token-0123456789"),
    (f"{TOKEN}\r\n", TOKEN),
])
def test_the_token_is_the_first_line_of_its_file(tmp_path: Path, text: str, token: str) -> None:
    path = tmp_path / "token"
    path.write_text(text, encoding="utf-8")
    assert read_token(path) == token


@pytest.mark.parametrize("text", ["", "   \n\n", "a" * 15, "short\n" + "a" * 40])
def test_a_token_shorter_than_16_characters_is_refused_at_line_1(tmp_path: Path, text: str) -> None:
    path = tmp_path / "token"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(DescriptionError, match="at least 16 characters") as caught:
        read_token(path)
    assert (caught.value.file, caught.value.line) == (str(path), 1)


def test_an_empty_token_file_is_said_to_hold_no_character(tmp_path: Path) -> None:
    path = tmp_path / "token"
    path.write_text("\n \n", encoding="utf-8")
    with pytest.raises(DescriptionError, match="found 0$"):
        read_token(path)


def test_a_missing_token_file_is_refused_naming_it(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match="cannot read the token file") as caught:
        read_token(tmp_path / "none")
    assert caught.value.file == str(tmp_path / "none")


@pytest.fixture
def ascii_locale() -> Iterator[None]:
    """The process's locale is C (ASCII), as on a machine where no UTF-8 locale is set."""
    before = locale.setlocale(locale.LC_CTYPE)
    locale.setlocale(locale.LC_CTYPE, "C")
    try:
        yield
    finally:
        locale.setlocale(locale.LC_CTYPE, before)


@pytest.mark.usefixtures("ascii_locale")
def test_the_token_file_is_read_as_utf8_whatever_the_locale(tmp_path: Path) -> None:
    path = tmp_path / "token"
    path.write_bytes("geheimes-Passwort-für-die-Zelle\n".encode())
    assert read_token(path) == "geheimes-Passwort-für-die-Zelle"


def test_a_token_file_that_is_not_utf8_is_refused_naming_it(tmp_path: Path) -> None:
    path = tmp_path / "token"
    path.write_bytes("geheimes-Passwort-für-die-Zelle\n".encode("latin-1"))
    with pytest.raises(DescriptionError, match=r"the token file is not UTF-8 text \(byte 20\)$") as caught:
        read_token(path)
    assert caught.value.file == str(path)


def test_a_new_token_is_32_random_url_safe_characters_and_reads_back(tmp_path: Path) -> None:
    tokens = {new_token() for _ in range(20)}
    assert len(tokens) == 20
    assert all(len(t) == 32 and t.replace("-", "").replace("_", "").isalnum() for t in tokens)
    path = tmp_path / "token"
    path.write_text(next(iter(tokens)), encoding="utf-8")
    assert read_token(path) in tokens


# --- who is on loopback --------------------------------------------------------------------


@pytest.mark.parametrize(("host", "loopback"), [
    ("127.0.0.1", True), ("127.45.6.7", True), ("::1", True), ("::1%lo", True), ("localhost", True),
    ("203.0.113.7", False), ("10.0.0.1", False), ("fe80::1%eth0", False), ("::ffff:203.0.113.7", False),
    ("localhost.example.org", False), ("127.0.0.1.example.org", False), ("", False), (None, False),
    ("::1%", False), ("127.0.0.1%lo", False),
])
def test_only_loopback_addresses_count_as_this_host(host: str | None, loopback: bool) -> None:
    assert is_loopback(host) is loopback


# --- requests: the token in the header, or in the query for reads from other hosts ---------


async def status(hmi: Hmi, client: tuple[str, int], method: str, url: str,
                 headers: dict[str, str] | None = None) -> httpx.Response:
    transport = httpx.ASGITransport(app=hmi.app, client=client)
    async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as c:
        return await c.request(method, url, headers=headers or {})


REMOTE = ("203.0.113.7", 40000)


@pytest.mark.parametrize("authorization", [f"Bearer {TOKEN}", f"bearer {TOKEN}", f"BEARER   {TOKEN}  "])
async def test_the_bearer_scheme_is_read_in_any_case_and_spacing(hmi: Hmi, authorization: str) -> None:
    res = await status(hmi, REMOTE, "GET", "/api/processes", {"Authorization": authorization})
    assert res.status_code == 200


@pytest.mark.parametrize("authorization", [f"Bearer{TOKEN}", f"Token {TOKEN}", f"Bearer {TOKEN[:-1]}",
                                           f"Bearer {TOKEN}x", "Bearer", TOKEN])
async def test_a_token_not_given_exactly_as_bearer_is_refused(hmi: Hmi, authorization: str) -> None:
    res = await status(hmi, ("127.0.0.1", 50000), "POST", "/api/runs/x/stop", {"Authorization": authorization})
    assert res.status_code == 401


@pytest.mark.parametrize(("query", "code"), [(f"?token={TOKEN}", 200), ("?token=", 401), ("?token=wrong", 401),
                                             (f"?token={TOKEN[:-1]}", 401), ("", 401)])
async def test_a_read_from_another_host_may_carry_the_token_in_the_query(hmi: Hmi, query: str, code: int) -> None:
    res = await status(hmi, REMOTE, "GET", "/api/processes" + query)
    assert res.status_code == code


async def test_the_token_in_the_query_does_not_authorise_a_change(hmi: Hmi) -> None:
    res = await status(hmi, ("127.0.0.1", 50000), "POST", f"/api/runs/x/stop?token={TOKEN}")
    assert res.status_code == 401


async def test_a_refused_client_is_told_how_to_send_the_token(hmi: Hmi) -> None:
    for client, method, url in ((REMOTE, "GET", "/api/processes"), (("127.0.0.1", 1), "POST", "/api/runs/x/stop")):
        res = await status(hmi, client, method, url)
        assert res.status_code == 401
        assert res.headers["www-authenticate"] == 'Bearer realm="pnp"'
        assert "Authorization: Bearer TOKEN" in res.json()["detail"]


@pytest.mark.parametrize(("headers", "code"), [({}, 401), ({"Authorization": "Bearer wrong-token-0123456789"}, 401),
                                             ({"Authorization": f"Bearer {TOKEN}"}, 200)])
async def test_a_client_without_an_address_reads_only_with_the_token(hmi: Hmi, headers: dict[str, str],
                                                                     code: int) -> None:
    """A server that knows no client address (one on a Unix socket) passes none: not loopback, so the token."""
    transport = httpx.ASGITransport(app=hmi.app, client=None)  # type: ignore[arg-type]
    async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as c:
        res = await c.get("/api/processes", headers=headers)
    assert res.status_code == code


async def test_a_read_from_ipv6_loopback_needs_no_token(hmi: Hmi) -> None:
    res = await status(hmi, ("::1", 50000), "GET", "/api/processes")
    assert res.status_code == 200


# --- the page's headers --------------------------------------------------------------------


async def test_the_page_and_the_api_carry_the_strict_policy_and_the_docs_do_not(hmi: Hmi) -> None:
    for url in ("/", "/api/processes"):
        res = await status(hmi, ("127.0.0.1", 1), "GET", url)
        assert "script-src 'self'" in res.headers["content-security-policy"]
        assert "frame-ancestors 'none'" in res.headers["content-security-policy"]
        assert (res.headers["x-content-type-options"], res.headers["referrer-policy"]) == ("nosniff", "no-referrer")
    for url in ("/docs", "/redoc"):
        res = await status(hmi, ("127.0.0.1", 1), "GET", url)
        assert res.status_code == 200 and "content-security-policy" not in res.headers
        assert res.headers["x-content-type-options"] == "nosniff"


async def test_the_headers_are_added_to_a_response_that_starts_without_any() -> None:
    """An ASGI application may leave the headers out of its response's start: the middleware adds its own."""
    async def bare(scope: Scope, receive: Receive, send: Send) -> None:
        await send({"type": "http.response.start", "status": 204})
        await send({"type": "http.response.body", "body": b""})

    transport = httpx.ASGITransport(app=SecurityHeaders(bare))
    async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as c:
        res = await c.get("/api/cell")
    assert res.status_code == 204 and res.headers["x-content-type-options"] == "nosniff"
    assert "frame-ancestors 'none'" in res.headers["content-security-policy"]


async def _start_header_names(app: ASGIApp, headers: list[tuple[bytes, bytes]]) -> list[bytes]:
    """The header names an ASGI application sends in the start of its response to a POST of 11 bytes."""
    sent: list[Message] = []

    async def receive() -> Message:
        return {"type": "http.request", "body": b"x" * 11, "more_body": False}

    async def send(message: Message) -> None:
        sent.append(message)

    scope = {"type": "http", "method": "POST", "path": "/", "headers": headers, "query_string": b""}
    await app(scope, receive, send)
    return [name for name, _ in sent[0]["headers"]]


async def test_header_names_are_sent_in_lower_case_as_asgi_requires() -> None:
    """A server sends the names as given, and HTTP/2 refuses a response with a name in upper case."""
    names = await _start_header_names(SecurityHeaders(echo), [])
    assert {b"x-content-type-options", b"referrer-policy", b"content-security-policy"} <= set(names)
    names = await _start_header_names(BodyLimit(echo, limit=10), [(b"content-length", b"11")])
    assert names == [b"content-type", b"content-length"]


async def test_the_server_starts_and_stops_the_application_through_its_middlewares(hmi: Hmi) -> None:
    """A server sends the lifespan (startup, then shutdown) through the security middlewares to the application."""
    incoming = [{"type": "lifespan.startup"}, {"type": "lifespan.shutdown"}]
    sent: list[str] = []

    async def receive() -> Message:
        return incoming.pop(0)

    async def send(message: Message) -> None:
        sent.append(message["type"])

    await hmi.app({"type": "lifespan", "asgi": {"version": "3.0", "spec_version": "2.0"}, "state": {}}, receive, send)
    assert sent == ["lifespan.startup.complete", "lifespan.shutdown.complete"]


# --- the body limit, on a small application ----------------------------------------------


async def echo(scope: Scope, receive: Receive, send: Send) -> None:
    """Reads the whole body and answers its length."""
    if scope["type"] == "lifespan":
        return
    size, more = 0, True
    while more:
        message = await receive()
        size += len(message.get("body", b""))
        more = message.get("more_body", False)
    await send({"type": "http.response.start", "status": 200, "headers": []})
    await send({"type": "http.response.body", "body": str(size).encode()})


@pytest.fixture
async def limited() -> AsyncIterator[httpx.AsyncClient]:
    from fastapi import FastAPI
    from starlette.middleware.exceptions import ExceptionMiddleware

    app = FastAPI()
    app.mount("/", ExceptionMiddleware(BodyLimit(SecurityHeaders(echo), limit=10)))
    async with httpx.AsyncClient(transport=httpx.ASGITransport(app=app), base_url="http://127.0.0.1") as c:
        yield c


def chunks(*parts: bytes) -> AsyncIterator[bytes]:
    async def gen() -> AsyncIterator[bytes]:
        for part in parts:
            yield part
    return gen()


async def test_a_body_up_to_the_limit_is_read_whole(limited: httpx.AsyncClient) -> None:
    assert (await limited.post("/", content=b"x" * 10)).text == "10"
    assert (await limited.post("/", content=chunks(b"xxxxx", b"xxxxx"))).text == "10"


async def test_a_declared_length_over_the_limit_is_refused_before_reading(limited: httpx.AsyncClient) -> None:
    res = await limited.post("/", content=b"x" * 11)
    assert res.status_code == 413
    assert res.json() == {"detail": "the request body is larger than the 10 bytes accepted"}
    assert res.headers["content-type"] == "application/json"
    assert res.headers["content-length"] == str(len(res.content))


async def test_a_chunked_body_over_the_limit_is_refused_as_it_streams(limited: httpx.AsyncClient) -> None:
    res = await limited.post("/", content=chunks(b"xxxxx", b"xxxxx", b"x"))
    assert res.status_code == 413
    assert "larger than the 10 bytes" in res.text
