"""The controller's HTTP reading for UPnP, against a real aiohttp server on loopback:
bodies are read to their end, within the limit, however the server writes them."""

from __future__ import annotations

from collections.abc import AsyncIterator

import pytest
from aiohttp import web
from async_upnp_client.client import UpnpRequester
from async_upnp_client.const import HttpRequest
from async_upnp_client.exceptions import UpnpCommunicationError

from plugnproduce.protocols.upnp.boundary import NoRedirectRequester

LIMIT = 1024 * 1024


async def chunked(request: web.Request) -> web.StreamResponse:
    response = web.StreamResponse()
    response.enable_chunked_encoding()
    await response.prepare(request)
    for n in range(int(request.query["chunks"])):
        await response.write(f"<!-- {n:06d} -->".encode() + b"x" * 4000 + b"\n")
    await response.write_eof()
    return response


async def whole(request: web.Request) -> web.Response:
    return web.Response(body=b"y" * int(request.query["size"]))


@pytest.fixture
async def server() -> AsyncIterator[str]:
    app = web.Application()
    app.router.add_get("/chunked", chunked)
    app.router.add_get("/whole", whole)
    runner = web.AppRunner(app)
    await runner.setup()
    site = web.TCPSite(runner, "127.0.0.1", 0)
    await site.start()
    port = runner.addresses[0][1]
    yield f"http://127.0.0.1:{port}"
    await runner.cleanup()


async def get(requester: UpnpRequester, url: str) -> str:
    response = await requester.async_http_request(HttpRequest("GET", url, {}, None))
    return str(response.body)


async def test_a_chunked_body_is_read_to_its_end(server: str) -> None:
    body = await get(NoRedirectRequester(5.0, LIMIT), f"{server}/chunked?chunks=50")
    assert body.count("\n") == 50 and body.rstrip().endswith("x")


async def test_a_large_single_write_is_read_to_its_end(server: str) -> None:
    assert len(await get(NoRedirectRequester(5.0, LIMIT), f"{server}/whole?size=600000")) == 600000


async def test_a_chunked_body_over_the_limit_is_refused(server: str) -> None:
    with pytest.raises(UpnpCommunicationError, match="larger than the 1048576 bytes accepted"):
        await get(NoRedirectRequester(5.0, LIMIT), f"{server}/chunked?chunks=400")
