"""The edge between async-upnp-client and the project: network, trust rule, errors.

* :class:`SsdpNetwork` says where SSDP runs (loopback by default).
* The trust rule: a device is trusted only for the address it was discovered at.
  Every HTTP request made for a device goes through :class:`TrustedRequester`,
  which refuses a URL on any other host with :class:`UntrustedUrlError` before a
  connection is made.
* :func:`upnp_errors` turns the library's exceptions into
  :mod:`plugnproduce.errors`, chained ``from`` the original.
"""

from __future__ import annotations

import asyncio
import ipaddress
import os
import socket
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TypeVar
from urllib.parse import SplitResult, urljoin, urlsplit

import aiohttp
from async_upnp_client.client import UpnpRequester
from async_upnp_client.const import HttpRequest, HttpResponse
from async_upnp_client.exceptions import (
    UpnpActionError,
    UpnpCommunicationError,
    UpnpConnectionError,
    UpnpConnectionTimeoutError,
    UpnpContentError,
    UpnpError,
    UpnpResponseError,
)
from async_upnp_client.ssdp import SSDP_IP_V4, SSDP_PORT

from plugnproduce.errors import (
    ProtocolConnectionError,
    ProtocolError,
    ProtocolTimeout,
    RemoteError,
    excerpt,
    shorten_words,
    tidy,
)
from plugnproduce.protocols.interface import LOOPBACK_ADDRESS, chosen_address

T = TypeVar("T")


@dataclass(frozen=True)
class SsdpNetwork:
    """Where SSDP runs: the local address all sockets use, and the multicast group and port.

    ``interface`` is an IPv4 address of this machine: SSDP sends its multicast out of that
    interface and joins the group on it, and the devices' servers listen on it. The default,
    :data:`LOOPBACK`, keeps everything on ``127.0.0.1`` with the standard group
    ``239.255.255.250:1900``. A different ``port`` gives a private SSDP
    "network" (tests use a free port so that parallel runs do not see each other).
    """

    interface: str = LOOPBACK_ADDRESS
    group: str = SSDP_IP_V4
    port: int = SSDP_PORT

    @property
    def source(self) -> tuple[str, int]:
        """The local address as async-upnp-client wants it: ``(interface, 0)``."""
        return (self.interface, 0)

    @property
    def target(self) -> tuple[str, int]:
        """The multicast group and port SSDP messages go to."""
        return (self.group, self.port)


LOOPBACK = SsdpNetwork()
"""SSDP on the loopback interface, standard group and port."""

SSDP_PORT_VARIABLE = "PNP_SSDP_PORT"
"""Environment variable naming another SSDP port, for a private simulated cell (see :func:`network_from_env`)."""


def private_network(interface: str = LOOPBACK_ADDRESS) -> SsdpNetwork:
    """SSDP on a free port of ``interface`` (an address): a network only the devices and controller told about it
    share."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind((interface, 0))
        return SsdpNetwork(interface=interface, port=int(sock.getsockname()[1]))


def network_from_env(interface: str | None = None) -> SsdpNetwork:
    """SSDP on the interface the command line chose and on the standard port, or the one ``PNP_SSDP_PORT`` names,
    so that ``pnp sim up`` and ``pnp discover`` started with the same values see each other and nobody else.

    ``interface``: the ``--interface`` option, a name or an address; without it ``PNP_INTERFACE``, else loopback
    (see :func:`~plugnproduce.protocols.interface.chosen_address`).
    """
    address = chosen_address(interface)
    value = os.environ.get(SSDP_PORT_VARIABLE, "")
    if not value:
        return SsdpNetwork(interface=address)
    if not value.isdigit() or not 0 < int(value) < 65536:
        raise ProtocolError(f"{SSDP_PORT_VARIABLE}={value!r}: expected a UDP port number (1-65535)")
    return SsdpNetwork(interface=address, port=int(value))


IP_MULTICAST_ALL = getattr(socket, "IP_MULTICAST_ALL", 49)
"""Linux's socket option (``<linux/in.h>``; Python 3.11 does not name it): 0 keeps a socket to its own memberships."""


def hear_only_the_interface(transport: object) -> None:
    """Have an SSDP socket bound to the group's port receive the group's datagrams only from its own interface.

    async-upnp-client joins the group on the chosen interface, but binds the socket to every address; Linux then
    hands it the group's datagrams arriving on *any* interface some other socket joined it on (a device on loopback
    would be heard by a controller on ``eth0``). ``IP_MULTICAST_ALL`` 0 limits it to its own membership.

    Only the controller's listeners are so limited. A device's search responder is not: with two such limited
    sockets on the group's port of one host, Linux was seen to drop announcements arriving on the chosen
    interface, and a device that hears a search from elsewhere only answers it with its own address.
    """
    sock = getattr(transport, "get_extra_info", lambda _name: None)("socket")
    if sock is not None and sys.platform.startswith("linux") and sock.family == socket.AF_INET:
        sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)


class UntrustedUrlError(ProtocolError):
    """A device pointed at a URL on another host than the one it was discovered at."""


def _host_key(host: str) -> str:
    try:
        return str(ipaddress.ip_address(host))
    except ValueError:
        return host.lower()


def check_trusted(url: str, trusted_host: str, what: str) -> str:
    """Return ``url`` if it is an ``http`` URL on ``trusted_host``; else raise :class:`UntrustedUrlError`."""
    try:
        parts: SplitResult | None = urlsplit(url)
    except ValueError:
        parts = None
    if parts is None or parts.scheme != "http" or parts.hostname is None:
        raise UntrustedUrlError(f"{what}: {excerpt(url)!r} is refused; expected an http URL on host {trusted_host}")
    host = parts.hostname
    if _host_key(host) != _host_key(trusted_host):
        raise UntrustedUrlError(
            f"{what}: {excerpt(url)!r} points at host {excerpt(host)}, but the device was discovered at "
            f"{trusted_host}; "
            "a device is trusted only for the address it was discovered at, so the URL is refused"
        )
    return url


def resolve_trusted(base_url: str, reference: str, trusted_host: str, what: str) -> str:
    """Resolve ``reference`` against ``base_url`` and check the result is on ``trusted_host``."""
    try:
        url = urljoin(base_url, reference.strip())
    except ValueError as exc:
        raise UntrustedUrlError(f"{what}: {excerpt(reference)!r} is not a URL") from exc
    return check_trusted(url, trusted_host, what)


class NoRedirectRequester(UpnpRequester):
    """async-upnp-client's plain aiohttp requester, but following no redirect and reading at most ``limit`` bytes.

    A redirect could lead to another host, past the trust rule; an answer larger
    than any description could be is refused. Errors are the library's own, so its
    logic (e.g. re-subscribing) keeps working.
    """

    def __init__(self, timeout: float, limit: int) -> None:
        self._timeout = aiohttp.ClientTimeout(total=timeout)
        self._limit = limit

    async def async_http_request(self, http_request: HttpRequest) -> HttpResponse:
        """Do one HTTP request in a session of its own."""
        try:
            async with aiohttp.ClientSession(timeout=self._timeout) as session:
                async with session.request(
                    http_request.method,
                    http_request.url,
                    headers=dict(http_request.headers or {}),
                    data=http_request.body,
                    allow_redirects=False,
                ) as response:
                    body = (await self._read_body(response)).decode(response.charset or "utf-8")
                    return HttpResponse(response.status, response.headers, body)
        except TimeoutError as exc:
            raise UpnpConnectionTimeoutError(repr(exc)) from exc
        except aiohttp.ClientConnectionError as exc:
            raise UpnpConnectionError(repr(exc)) from exc
        except (aiohttp.ClientError, UnicodeDecodeError, LookupError) as exc:
            raise UpnpCommunicationError(repr(exc)) from exc


    async def _read_body(self, response: aiohttp.ClientResponse) -> bytes:
        """The whole body, read to its end (a single read returns only what is buffered), within the limit."""
        chunks: list[bytes] = []
        size = 0
        async for chunk in response.content.iter_chunked(64 * 1024):
            size += len(chunk)
            if size > self._limit:
                raise UpnpCommunicationError(f"answer larger than the {self._limit} bytes accepted")
            chunks.append(chunk)
        return b"".join(chunks)


class TrustedRequester(UpnpRequester):
    """A requester that only talks to one host: the address the device was discovered at."""

    def __init__(self, inner: UpnpRequester, trusted_host: str, device: str) -> None:
        self._inner = inner
        self.trusted_host = trusted_host
        self._device = device

    async def async_http_request(self, http_request: HttpRequest) -> HttpResponse:
        """Refuse a request to another host, else pass it on."""
        check_trusted(http_request.url, self.trusted_host, f"{http_request.method} for {self._device}")
        return await self._inner.async_http_request(http_request)


MAX_REASON = 120
"""Most characters of a library's reason a message carries (it may quote what a device sent)."""


def reason(exc: BaseException) -> str:
    """A readable reason from a library exception (whose ``args`` may hold ``None`` padding).

    One line, quoting short (:func:`~plugnproduce.errors.tidy`): a library's exception may carry
    what a device sent.
    """
    parts = [str(a) for a in exc.args if a is not None and str(a)]
    return tidy(shorten_words("; ".join(parts)), MAX_REASON) or type(exc).__name__


@contextmanager
def upnp_errors(what: str) -> Iterator[None]:
    """Turn async-upnp-client and aiohttp exceptions raised inside into project errors.

    ``what`` says what was being done, and with which device; it starts every message.
    Project errors (e.g. :class:`UntrustedUrlError`) pass through unchanged.
    """
    try:
        yield
    except ProtocolError:
        raise
    except (UpnpConnectionTimeoutError, TimeoutError) as exc:
        raise ProtocolTimeout(f"{what}: no answer in time") from exc
    except UpnpActionError as exc:
        raise RemoteError(
            f"{what}: the device answered with UPnP error {exc.error_code} ({exc.error_desc or 'no description'})"
        ) from exc
    except UpnpResponseError as exc:
        raise RemoteError(f"{what}: the device answered HTTP {exc.status}; expected 200") from exc
    except (UpnpConnectionError, aiohttp.ClientConnectionError, ConnectionError) as exc:
        raise ProtocolConnectionError(f"{what}: cannot connect ({reason(exc)})") from exc
    except UpnpContentError as exc:
        raise RemoteError(f"{what}: the device's answer cannot be read ({reason(exc)})") from exc
    except (UpnpCommunicationError, aiohttp.ClientError, OSError) as exc:
        raise ProtocolConnectionError(f"{what}: communication failed ({reason(exc)})") from exc
    except UpnpError as exc:
        raise ProtocolError(f"{what}: {reason(exc)}") from exc


class ChangeSignal:
    """Wake coroutines waiting for a condition whenever something new arrives.

    The library calls plain functions (never awaits coroutine callbacks); those
    call :meth:`notify`, and coroutines :meth:`wait_for` a condition with a timeout.
    """

    def __init__(self) -> None:
        self._event = asyncio.Event()

    def notify(self) -> None:
        """Something changed: let every waiter look again."""
        self._event.set()

    async def wait_for(self, probe: Callable[[], T | None], timeout: float, what: str) -> T:
        """Return ``probe()`` once it is not ``None``; :class:`ProtocolTimeout` after ``timeout`` seconds."""
        try:
            async with asyncio.timeout(timeout):
                while (found := probe()) is None:
                    self._event.clear()
                    await self._event.wait()
        except TimeoutError as exc:
            raise ProtocolTimeout(f"{what}: not within {timeout:g} s") from exc
        return found
