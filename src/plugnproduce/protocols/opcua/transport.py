"""The transport limits of every OPC UA connection the controller opens: to a device, or to a Local Discovery
Server. asyncua takes the limits a server's Acknowledge says as its own (and 0 would mean none), so a server could
send a message of any size and have it parsed; here each connection receives at most :data:`.spec.MAX_CHUNKS`
chunks of :data:`.spec.MAX_CHUNK` bytes per message, whatever the server says, and a larger answer ends it.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

from asyncua import Client, ua
from asyncua.common.connection import TransportLimits

from plugnproduce.protocols.opcua.spec import MAX_CHUNK, MAX_CHUNKS, MAX_MESSAGE

for _name in ("asyncua.client.client", "asyncua.client.ua_client", "asyncua.common.subscription",
              "asyncua.client.ua_client.UaClient", "asyncua.client.ua_client.UASocketProtocol", "asyncua.uaprotocol"):
    logging.getLogger(_name).setLevel(logging.CRITICAL)  # what goes wrong is reported to the user, not logged twice

LIMIT = f"{MAX_MESSAGE >> 20} MiB (at most {MAX_CHUNKS} chunks of {(MAX_CHUNK + 1) >> 10} KiB)"
"""The limit in words, for the messages that name it."""


class Limits(TransportLimits):  # type: ignore[misc]
    """The transport limits of one connection, held to ours whatever the server's Acknowledge says; a message
    beyond them sets ``beyond``."""

    beyond: asyncio.Event | None = None

    def update_client_limits(self, msg: ua.Acknowledge) -> None:
        super().update_client_limits(msg)
        _cap(self)

    def is_msg_size_within_limit(self, sz: int) -> bool:
        return self._noted(bool(super().is_msg_size_within_limit(sz)))

    def is_chunk_count_within_limit(self, sz: int) -> bool:
        return self._noted(bool(super().is_chunk_count_within_limit(sz)))

    def _noted(self, within: bool) -> bool:
        if not within and self.beyond is not None:
            self.beyond.set()
        return within


def _cap(limits: Any) -> None:
    limits.max_recv_buffer = _capped(limits.max_recv_buffer, MAX_CHUNK)
    limits.max_chunk_count = _capped(limits.max_chunk_count, MAX_CHUNKS)
    limits.max_message_size = _capped(limits.max_message_size, MAX_MESSAGE)


def _capped(value: int, limit: int) -> int:
    return limit if value <= 0 else min(value, limit)


def bound_transport(client: Client) -> asyncio.Event:
    """Hold every connection ``client`` opens (for its endpoints, its session) to the limits; the event returned
    is set once a server sends a message beyond them (the connection then ends)."""
    client.max_messagesize, client.max_chunkcount = MAX_MESSAGE, MAX_CHUNKS
    uaclient = client.uaclient
    make = uaclient._make_protocol
    beyond = asyncio.Event()

    def bounded() -> Any:
        protocol = make()
        protocol._connection._limits = Limits(MAX_CHUNK, MAX_CHUNK, MAX_CHUNKS, MAX_MESSAGE)
        protocol._connection._limits.beyond = beyond
        return protocol

    uaclient._make_protocol = bounded
    return beyond
