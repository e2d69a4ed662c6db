"""OPC UA discovery: a Local Discovery Server (LDS) the controller can run, and ``FindServers`` on one.

Any asyncua server answers ``RegisterServer`` and ``FindServers``, so the LDS is a plain asyncua server on its
own port (4840 by convention). A device's server registers with it under ``urn:plugnproduce:device:ID``
(:func:`~plugnproduce.protocols.opcua.spec.application_uri_for`); :func:`find_servers` lists those.
"""

from __future__ import annotations

import asyncio
import logging

from asyncua import Client, Server, ua

from plugnproduce.errors import ProtocolError
from plugnproduce.protocols.opcua.spec import APPLICATION_URI_PREFIX, MAX_CHUNKS, MAX_MESSAGE, format_endpoint

MAX_SERVERS = 256
"""Most servers a FindServers answer may list."""

logging.getLogger("asyncua.server.internal_server").setLevel(logging.ERROR)


class LocalDiscoveryServer:
    """An LDS on ``host``:``port`` (0: a free port); ``await start()``, ``await stop()``."""

    def __init__(self, host: str = "127.0.0.1", port: int = 4840) -> None:
        self._host, self._port = host, port
        self._server: Server | None = None
        self.endpoint: str | None = None

    async def start(self) -> None:
        """Listen (security mode None)."""
        server = Server()
        await server.init()
        server.set_server_name("Plug'n'Produce Local Discovery Server")
        server.set_endpoint(format_endpoint(self._host, self._port))
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        await server.set_application_uri("urn:plugnproduce:lds")
        await server.start()
        self._server = server
        self.endpoint = format_endpoint(self._host, server.bserver._server.sockets[0].getsockname()[1])

    async def stop(self) -> None:
        """Stop listening."""
        if self._server is not None:
            server, self._server = self._server, None
            await server.stop()


async def find_servers(lds: str, timeout: float) -> list[tuple[str, str]]:
    """The Plug'n'Produce devices registered with the LDS at ``lds``: (device id, discovery URL) each."""
    client = Client(lds, timeout=timeout)
    client.max_messagesize, client.max_chunkcount = MAX_MESSAGE, MAX_CHUNKS
    try:
        servers = await asyncio.wait_for(client.connect_and_find_servers(), timeout)
    except TimeoutError as exc:
        raise ProtocolError(f"Local Discovery Server {lds}: no FindServers answer within {timeout:g} s") from exc
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
