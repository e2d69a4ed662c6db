"""OPC UA discovery: a Local Discovery Server (LDS) the controller can run, and ``FindServers`` on one.

Any asyncua server answers ``RegisterServer`` and ``FindServers``, so the LDS is a plain asyncua server on its
own port (4840 by convention). A device's server registers with it under ``urn:plugnproduce:device:ID``
(:func:`~plugnproduce.protocols.opcua.spec.application_uri_for`); :func:`find_servers` lists those.

A registration lasts :data:`KEEP` seconds unless renewed (a device renews every
:data:`~plugnproduce.protocols.opcua.spec.REGISTRATION_PERIOD`), and ends at once when the server says it goes
offline (``IsOnline`` false, as a device that stops says): so a device that stops, or dies, leaves the list.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import time
from typing import Any

from asyncua import Client, Server, ua

from plugnproduce.errors import ProtocolConnectionError, ProtocolError
from plugnproduce.protocols.opcua.space import new_server
from plugnproduce.protocols.opcua.spec import APPLICATION_URI_PREFIX, REGISTRATION_PERIOD, format_endpoint
from plugnproduce.protocols.opcua.transport import LIMIT, bound_transport

MAX_SERVERS = 256
"""Most servers a FindServers answer may list."""

MAX_REGISTERED = MAX_SERVERS - 1
"""Most registrations the LDS keeps at once: with itself, as many servers as a FindServers answer may list."""
MAX_TEXT = 200
"""Longest application URI, product URI, gateway URI or server name a registration may give (characters)."""
MAX_URLS = 4
"""Most discovery URLs a registration may give, each at most :data:`MAX_URL` characters."""
MAX_URL = 300

KEEP = 3 * REGISTRATION_PERIOD
"""Seconds a registration lasts without being renewed."""

logging.getLogger("asyncua.server.internal_server").setLevel(logging.ERROR)
logging.getLogger("asyncua.server.server").setLevel(logging.CRITICAL)  # security-None chatter, and a port taken
# is said by LocalDiscoveryServer.start in one line


class LocalDiscoveryServer:
    """An LDS on ``host``:``port`` (0: a free port); ``await start()``, ``await stop()``, or ``async with``.

    The simulated cell runs one beside its devices (``pnp sim up --serve-lds``), the controller one for the
    devices of the network (``pnp discover --serve-lds``, ``pnp serve --serve-lds``)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 4840, keep: float = KEEP) -> None:
        """``keep``: seconds a registration lasts unless renewed."""
        self._host, self._port, self.keep = host, port, keep
        self._server: Server | None = None
        self._renewed: dict[str, float] = {}  # application URI -> monotonic time of its last registration
        self._known: dict[str, Any] = {}
        self._register: Any = None
        self._find: Any = None
        self.registrations = 0
        """How many RegisterServer calls it took (first registrations and renewals)."""
        self.endpoint: str | None = None

    async def start(self) -> None:
        """Listen (security mode None)."""
        server = await new_server()  # the standard address space as kept, not built again
        server.set_server_name("Plug'n'Produce Local Discovery Server")
        server.set_endpoint(format_endpoint(self._host, self._port))
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        await server.set_application_uri("urn:plugnproduce:lds")
        internal = server.iserver
        self._known, self._register, self._find = internal._known_servers, internal.register_server, \
            internal.find_servers
        internal.register_server, internal.find_servers = self._on_register, self._on_find
        try:
            await server.start()
        except OSError as exc:
            raise ProtocolConnectionError(f"Local Discovery Server: cannot listen on "
                                          f"{format_endpoint(self._host, self._port)}: "
                                          f"{os.strerror(exc.errno) if exc.errno else exc}") from exc
        self._server = server
        self.endpoint = format_endpoint(self._host, server.bserver._server.sockets[0].getsockname()[1])

    def _on_register(self, registered: Any, conf: Any = None) -> None:
        """RegisterServer: a registration within the limits is taken or renewed; one going offline ends now."""
        self.registrations += 1
        uri = registered.ServerUri
        if not registered.IsOnline:  # the server goes offline: it leaves the list now
            self._known.pop(uri, None)
            self._renewed.pop(uri, None)
            return
        _check_registration(registered)
        if uri not in self._renewed and len(self._renewed) >= MAX_REGISTERED:
            self._expire(self._known)
            if len(self._renewed) >= MAX_REGISTERED:
                raise ua.UaStatusCodeError(ua.StatusCodes.BadResourceUnavailable)
        self._renewed[uri] = time.monotonic()
        self._register(registered, conf)

    def _on_find(self, params: Any, sockname: Any = None) -> Any:
        """FindServers: the registrations still kept (and the LDS itself)."""
        self._expire(self._known)
        return self._find(params, sockname)

    async def __aenter__(self) -> LocalDiscoveryServer:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.stop()

    def _expire(self, known: dict[str, Any]) -> None:
        """Forget the registrations not renewed within ``keep`` seconds."""
        now = time.monotonic()
        for uri, renewed in list(self._renewed.items()):
            if now - renewed > self.keep:
                known.pop(uri, None)
                del self._renewed[uri]

    async def stop(self) -> None:
        """Stop listening."""
        if self._server is not None:
            server, self._server = self._server, None
            await server.stop()


def _check_registration(registered: Any) -> None:
    """Refuse (``BadInvalidArgument``) a registration beyond the limits: so whatever registers, the LDS's
    FindServers answer stays well within the message limit of the controller that asks it."""
    names = registered.ServerNames or []
    texts = [registered.ServerUri, registered.ProductUri, registered.GatewayServerUri,
             *(getattr(n, "Text", None) for n in names[:1]), *(getattr(n, "Locale", None) for n in names[:1])]
    urls = registered.DiscoveryUrls or []
    if not registered.ServerUri or not names or len(names) > MAX_URLS or not urls or len(urls) > MAX_URLS \
            or any(len(t or "") > MAX_TEXT for t in texts) or any(len(u or "") > MAX_URL for u in urls):
        raise ua.UaStatusCodeError(ua.StatusCodes.BadInvalidArgument)


async def find_servers(lds: str, timeout: float) -> list[tuple[str, str]]:
    """The Plug'n'Produce devices registered with the LDS at ``lds``: (device id, discovery URL) each.

    The connection is held to the limits of a device's (:mod:`.transport`): an answer beyond them ends it, and
    the LDS is refused (a :class:`ProtocolError` naming it)."""
    client = Client(lds, timeout=timeout)
    beyond = bound_transport(client)
    try:
        servers = await asyncio.wait_for(_ask(client, beyond), timeout)
    except TimeoutError as exc:
        raise ProtocolError(f"Local Discovery Server {lds}: no FindServers answer within {timeout:g} s") from exc
    except _TooLarge as exc:
        raise ProtocolError(f"Local Discovery Server {lds}: its FindServers answer is larger than {LIMIT}") from exc
    except Exception as exc:  # a foreign server's failure is a refusal, never a crash
        raise ProtocolError(f"Local Discovery Server {lds}: FindServers failed: {str(exc)[:200]}") from exc
    if not isinstance(servers, list) or len(servers) > MAX_SERVERS:
        raise ProtocolError(f"Local Discovery Server {lds}: FindServers answered more than {MAX_SERVERS} servers")
    found = []
    for server in servers:
        uri, urls = getattr(server, "ApplicationUri", None), getattr(server, "DiscoveryUrls", None) or []
        if isinstance(uri, str) and uri.startswith(APPLICATION_URI_PREFIX) and urls and isinstance(urls[0], str):
            found.append((uri[len(APPLICATION_URI_PREFIX):][:128], urls[0][:300]))
    return found


class _TooLarge(Exception):
    """The server sent a message beyond the connection's limits."""


async def _ask(client: Client, beyond: asyncio.Event) -> Any:
    """FindServers, ended as soon as the server goes beyond the connection's limits (asyncua would wait for the
    answer the dropped message held until the timeout)."""
    asking = asyncio.ensure_future(client.connect_and_find_servers())
    told = asyncio.ensure_future(beyond.wait())
    try:
        await asyncio.wait((asking, told), return_when=asyncio.FIRST_COMPLETED)
        if beyond.is_set():
            raise _TooLarge
        return asking.result()
    finally:
        for task in (asking, told):
            if not task.done():
                task.cancel()
                with contextlib.suppress(BaseException):
                    await task
