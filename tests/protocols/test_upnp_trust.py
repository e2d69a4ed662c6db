"""The UPnP trust rule: a device is trusted only for the address it was discovered at.

Every URL a device names (its description, its services, the files it serves, a follow-up
request) must be plain ``http`` on that host; anything else is refused before a connection
is made. Redirects are not followed (they could lead elsewhere) and answers are bounded.
"""

from __future__ import annotations

import asyncio
import re
import uuid
from collections.abc import AsyncIterator, Awaitable, Callable

import pytest
from aiohttp import web
from async_upnp_client.client import UpnpRequester
from async_upnp_client.const import HttpRequest, HttpResponse
from async_upnp_client.exceptions import (
    UpnpCommunicationError,
    UpnpConnectionError,
    UpnpConnectionTimeoutError,
)

from plugnproduce.errors import ProtocolConnectionError, ProtocolTimeout, RemoteError
from plugnproduce.protocols.upnp import SsdpNetwork, UpnpDeviceServer, device_type_for
from plugnproduce.protocols.upnp.boundary import (
    NoRedirectRequester,
    TrustedRequester,
    UntrustedUrlError,
    check_trusted,
    resolve_trusted,
)
from plugnproduce.protocols.upnp.client import UpnpDeviceClient, load_device
from plugnproduce.protocols.upnp.discovery import FoundDevice, SearchHit, describe
from tests.lines import WAIT
from tests.protocols.test_upnp_loopback import FILES, SPEC, Recorder, free_udp_port


@pytest.mark.parametrize(("url", "host"), [
    ("http://127.0.0.1:8080/description.xml", "127.0.0.1"),
    ("http://127.0.0.1/", "127.0.0.1"),
    ("http://[::1]:80/d.xml", "::1"),
    ("http://[0:0:0:0:0:0:0:1]/d.xml", "::1"),
    ("http://LocalHost:8080/d.xml", "localhost"),
    ("http://device.local/d.xml", "DEVICE.local"),
    ("http://user@127.0.0.1/d.xml", "127.0.0.1"),
])
def test_an_http_url_on_the_discovery_host_is_trusted(url: str, host: str) -> None:
    assert check_trusted(url, host, "device x") == url


@pytest.mark.parametrize(("url", "needle"), [
    ("http://127.0.0.2/d.xml", "points at host 127.0.0.2, but the device was discovered at 127.0.0.1"),
    ("http://127.0.0.1@evil.example/d.xml", "points at host evil.example"),
    ("http://[::ffff:7f00:1]/d.xml", "points at host ::ffff:7f00:1"),
    ("http://localhost/d.xml", "points at host localhost"),
    ("https://127.0.0.1/d.xml", "expected an http URL on host 127.0.0.1"),
    ("file:///etc/passwd", "expected an http URL"),
    ("ftp://127.0.0.1/d.xml", "expected an http URL"),
    ("/etc/passwd", "expected an http URL"),
    ("http:///d.xml", "expected an http URL"),
    ("http://[::1/d.xml", "expected an http URL"),
    ("", "expected an http URL"),
])
def test_any_other_url_is_refused_naming_why(url: str, needle: str) -> None:
    with pytest.raises(UntrustedUrlError, match="^device x: ") as caught:
        check_trusted(url, "127.0.0.1", "device x")
    assert needle in str(caught.value)


@pytest.mark.parametrize(("reference", "resolved"), [
    ("chart.scxml", "http://127.0.0.1:9000/files/chart.scxml"),
    ("  /other/chart.scxml\n", "http://127.0.0.1:9000/other/chart.scxml"),
    ("http://127.0.0.1:9001/chart.scxml", "http://127.0.0.1:9001/chart.scxml"),
])
def test_a_reference_is_resolved_against_the_description_and_checked(reference: str, resolved: str) -> None:
    assert resolve_trusted("http://127.0.0.1:9000/files/d.xml", reference, "127.0.0.1", "chart") == resolved


@pytest.mark.parametrize(("reference", "needle"), [
    ("//evil.example/chart.scxml", "points at host evil.example"),
    ("http://evil.example/chart.scxml", "points at host evil.example"),
    ("file:///etc/passwd", "expected an http URL"),
    ("http://[::1", "is not a URL"),
])
def test_a_reference_to_another_host_or_scheme_is_refused(reference: str, needle: str) -> None:
    with pytest.raises(UntrustedUrlError, match="^chart: ") as caught:
        resolve_trusted("http://127.0.0.1:9000/files/d.xml", reference, "127.0.0.1", "chart")
    assert needle in str(caught.value)


class Recording(UpnpRequester):
    """A requester that answers every request with 200 and remembers the URLs it was asked for."""

    def __init__(self) -> None:
        self.urls: list[str] = []

    async def async_http_request(self, http_request: HttpRequest) -> HttpResponse:
        self.urls.append(http_request.url)
        return HttpResponse(200, {}, "answer")


async def test_a_follow_up_request_to_another_host_never_leaves_the_controller() -> None:
    inner = Recording()
    requester = TrustedRequester(inner, "127.0.0.1", "device gripper")
    with pytest.raises(UntrustedUrlError, match="^SUBSCRIBE for device gripper: .*points at host 10.0.0.9"):
        await requester.async_http_request(HttpRequest("SUBSCRIBE", "http://10.0.0.9/events", {}, None))
    assert inner.urls == []
    answer = await requester.async_http_request(HttpRequest("GET", "http://127.0.0.1:81/x", {}, None))
    assert (answer.status_code, answer.body, inner.urls) == (200, "answer", ["http://127.0.0.1:81/x"])


def test_a_host_name_that_only_case_folds_to_the_trusted_one_is_another_host() -> None:
    """``ß`` upper-cases to ``SS``: ``straße`` is still not ``strasse`` (host names are compared lower-cased)."""
    with pytest.raises(UntrustedUrlError, match="points at host straße.example"):
        check_trusted("http://straße.example/d.xml", "strasse.example", "device x")
    assert check_trusted("http://STRASSE.example/d.xml", "strasse.example", "device x")


async def test_describe_refuses_a_description_on_another_host_before_connecting() -> None:
    hit = SearchHit("uuid:gripper", "http://10.0.0.9:1/d.xml", "127.0.0.1")
    expected = ("device uuid:gripper at http://10.0.0.9:1/d.xml: 'http://10.0.0.9:1/d.xml' points at host 10.0.0.9, "
                "but the device was discovered at 127.0.0.1")
    with pytest.raises(UntrustedUrlError, match="^" + re.escape(expected)):
        await describe(hit, timeout=30.0)


async def test_an_unreachable_description_is_a_connection_error_naming_the_device() -> None:
    hit = SearchHit("uuid:gripper", "http://127.0.0.1:1/d.xml", "127.0.0.1")
    expected = "reading the description of device uuid:gripper at http://127.0.0.1:1/d.xml: cannot connect"
    with pytest.raises(ProtocolConnectionError, match="^" + re.escape(expected)):
        await describe(hit, timeout=30.0)


class Silent(UpnpRequester):
    """A requester whose requests never end (it has no bound of its own)."""

    async def async_http_request(self, http_request: HttpRequest) -> HttpResponse:
        await asyncio.Event().wait()
        raise AssertionError("never answered")


async def test_reading_a_description_is_bounded_even_when_the_requester_is_not() -> None:
    requester = TrustedRequester(Silent(), "127.0.0.1", "device x")
    async with asyncio.timeout(WAIT):  # the test's own guard against a reading that never ends
        with pytest.raises(ProtocolTimeout, match="^reading the description of device x: no answer within 0.05 s$"):
            await load_device("http://127.0.0.1:1/d.xml", requester, "device x", 0.05)


async def test_connect_refuses_a_location_on_another_host() -> None:
    found = FoundDevice("uuid:gripper", "http://10.0.0.9:1/d.xml", "type", "name", "127.0.0.1")
    with pytest.raises(UntrustedUrlError, match="discovered at 127.0.0.1"):
        await UpnpDeviceClient.from_found(found, timeout=30.0)


async def test_describe_without_a_location_is_a_remote_error() -> None:
    with pytest.raises(RemoteError, match="gave no description URL"):
        await describe(SearchHit("uuid:gripper", None, "127.0.0.1"))  # type: ignore[arg-type]


# --- the HTTP reader: no redirects, bounded answers ------------------------------------------


async def redirect(request: web.Request) -> web.Response:
    raise web.HTTPFound("http://10.0.0.9/elsewhere.xml")


async def sized(request: web.Request) -> web.Response:
    return web.Response(body=b"z" * int(request.query["size"]))


async def plain(request: web.Request) -> web.Response:
    response = web.Response(body="caf\u00e9".encode())
    response.headers["Content-Type"] = "text/xml"  # no charset: UTF-8 is assumed
    return response


async def latin(request: web.Request) -> web.Response:
    return web.Response(body="caf\u00e9".encode("latin-1"), content_type="text/xml", charset="utf-8")


@pytest.fixture
async def server() -> AsyncIterator[str]:
    app = web.Application()
    app.router.add_get("/redirect", redirect)
    app.router.add_get("/sized", sized)
    app.router.add_get("/latin", latin)
    app.router.add_get("/plain", plain)
    runner = web.AppRunner(app)
    await runner.setup()
    site = web.TCPSite(runner, "127.0.0.1", 0)
    await site.start()
    yield f"http://127.0.0.1:{runner.addresses[0][1]}"
    await runner.cleanup()


async def get(requester: UpnpRequester, url: str) -> HttpResponse:
    return await requester.async_http_request(HttpRequest("GET", url, {}, None))


async def test_a_redirect_is_not_followed(server: str) -> None:
    answer = await get(NoRedirectRequester(5.0, 100), f"{server}/redirect")
    assert answer.status_code == 302 and answer.headers["Location"] == "http://10.0.0.9/elsewhere.xml"


async def test_an_answer_up_to_the_limit_is_read_and_one_byte_more_is_refused(server: str) -> None:
    assert (await get(NoRedirectRequester(5.0, 100), f"{server}/sized?size=100")).body == "z" * 100
    with pytest.raises(UpnpCommunicationError, match="larger than the 100 bytes accepted"):
        await get(NoRedirectRequester(5.0, 100), f"{server}/sized?size=101")


async def test_an_answer_without_a_charset_is_read_as_utf8(server: str) -> None:
    assert (await get(NoRedirectRequester(5.0, 100), f"{server}/plain")).body == "caf\u00e9"


async def test_an_answer_that_is_not_its_declared_encoding_is_a_communication_error(server: str) -> None:
    with pytest.raises(UpnpCommunicationError, match="UnicodeDecodeError"):
        await get(NoRedirectRequester(5.0, 100), f"{server}/latin")


async def test_an_unreachable_device_is_a_connection_error(server: str) -> None:
    with pytest.raises(UpnpConnectionError):
        await get(NoRedirectRequester(5.0, 100), "http://127.0.0.1:1/d.xml")


async def test_a_device_that_does_not_answer_in_time_is_a_timeout() -> None:
    done = asyncio.Event()

    async def silent(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        await done.wait()  # reads the request, never answers
        writer.close()

    listening = await asyncio.start_server(silent, "127.0.0.1", 0)
    port = listening.sockets[0].getsockname()[1]
    try:
        with pytest.raises(UpnpConnectionTimeoutError):
            await get(NoRedirectRequester(0.2, 100), f"http://127.0.0.1:{port}/d.xml")
    finally:
        done.set()
        listening.close()
        await listening.wait_closed()
        await asyncio.sleep(0)  # let the handler close its side


# --- a device whose description names its files elsewhere ---------------------------------


class Elsewhere(UpnpDeviceServer):
    """A device whose description names its chart (or none) where it likes."""

    def __init__(self, chart_url: str | None) -> None:
        super().__init__(f"robot-{uuid.uuid4().hex[:8]}", "Hostile robot", device_type_for("Robot"), SPEC,
                         Recorder(), files=FILES, network=SsdpNetwork(port=free_udp_port()))
        self.chart_url = chart_url

    async def _description(self, request: web.Request) -> web.Response:
        text = (await super()._description(request)).text or ""
        if self.chart_url is None:
            text = re.sub(r"<pnp:chartURL[^>]*>[^<]*</pnp:chartURL>", "", text)
        else:
            text = text.replace("/pnp/robot.scxml", self.chart_url)
        return web.Response(text=text, content_type="text/xml", charset="utf-8")


@pytest.mark.parametrize(("chart_url", "needle"), [
    ("http://10.0.0.9/robot.scxml", "points at host 10.0.0.9"),
    ("//10.0.0.9/robot.scxml", "points at host 10.0.0.9"),
    ("file:///etc/passwd", "expected an http URL"),
])
async def test_a_chart_named_on_another_host_is_refused_before_any_request(chart_url: str, needle: str) -> None:
    async with Elsewhere(chart_url) as device:
        async with await UpnpDeviceClient.connect(str(device.location), "127.0.0.1", timeout=30.0) as client:
            with pytest.raises(UntrustedUrlError, match=f"^pnp:chartURL of .*{needle}"):
                await client.fetch_files()


async def test_a_description_naming_no_chart_is_a_remote_error() -> None:
    async with Elsewhere(None) as device:
        async with await UpnpDeviceClient.connect(str(device.location), "127.0.0.1", timeout=30.0) as client:
            with pytest.raises(RemoteError, match="has no pnp:chartURL element"):
                await client.fetch_files()


async def test_a_device_describing_itself_with_another_udn_is_refused() -> None:
    async with Elsewhere("/pnp/robot.scxml") as device:
        found = FoundDevice("uuid:someone-else", str(device.location), "type", "name", "127.0.0.1")
        with pytest.raises(RemoteError, match="describes itself as .*; discovered as uuid:someone-else"):
            await UpnpDeviceClient.from_found(found, timeout=30.0)
        with pytest.raises(RemoteError, match="its description names UDN .*; it was discovered as uuid:someone-else"):
            await describe(SearchHit("uuid:someone-else", str(device.location), "127.0.0.1"), timeout=30.0)
        hit = await describe(SearchHit(device.udn.upper(), str(device.location), "127.0.0.1"), timeout=30.0)
        assert (hit.udn, hit.location, hit.source_host, hit.friendly_name) == \
            (device.udn.upper(), str(device.location), "127.0.0.1", "Hostile robot")


async def test_a_found_device_is_connected_whatever_the_case_of_its_udn_with_the_timeout_given() -> None:
    async with Elsewhere("/pnp/robot.scxml") as device:
        for udn in (device.udn.upper(), device.udn.lower()):
            found = FoundDevice(udn, str(device.location), "type", "name", "127.0.0.1")
            async with await UpnpDeviceClient.from_found(found, timeout=7.5) as client:
                assert (client.udn, client.trusted_host, client.timeout) == (device.udn, "127.0.0.1", 7.5)


class SecureService(Elsewhere):
    """A device on loopback whose service description is named with ``https`` on its own host."""

    async def _description(self, request: web.Request) -> web.Response:
        text = (await super()._description(request)).text or ""
        text = text.replace("<SCPDURL>/", f"<SCPDURL>https://{request.host}/")
        return web.Response(text=text, content_type="text/xml", charset="utf-8")


async def test_a_service_description_named_over_https_is_refused_naming_the_device() -> None:
    async with SecureService("/pnp/robot.scxml") as device:
        what = f"GET for device {device.udn} at {device.location}: 'https://127.0.0.1:"
        with pytest.raises(UntrustedUrlError, match="^" + re.escape(what) + ".*expected an http URL on host 127.0.0.1"):
            await describe(SearchHit(device.udn, str(device.location), "127.0.0.1"), timeout=30.0)


class Slow(Elsewhere):
    """A device that answers every HTTP request, each well within the timeout, but only after a while."""

    delay = 0.3

    def _app(self) -> web.Application:
        app = super()._app()

        @web.middleware
        async def late(request: web.Request, handler: Callable[[web.Request], Awaitable[web.StreamResponse]]
                       ) -> web.StreamResponse:
            await asyncio.sleep(self.delay)
            return await handler(request)

        app.middlewares.append(late)
        return app


async def test_reading_a_description_is_bounded_as_a_whole_not_per_request() -> None:
    """A device cannot hold the controller for a timeout per request: description and service description
    together (two requests of 0.3 s each) take longer than the 0.5 s given."""
    async with Slow("/pnp/robot.scxml") as device:
        with pytest.raises(ProtocolTimeout, match=": no answer within 0.5 s$"):
            await describe(SearchHit(device.udn, str(device.location), "127.0.0.1"), timeout=0.5)
