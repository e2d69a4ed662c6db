"""The edge to asyncio: one TCP connection carrying length-prefixed frames, OS errors turned into project errors.

:class:`FrameLink` is an :class:`asyncio.Protocol`: it cuts the byte stream into
frames and hands each complete one to its :class:`Receiver` right away, on the
event loop (no reader task, no extra hop). Both the device side (one link per
controller) and the controller side use it. A frame is written with one
``write`` call, so frames never interleave.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Protocol, cast

from plugnproduce.errors import ProtocolConnectionError
from plugnproduce.protocols.xirp.codec import HEADER
from plugnproduce.protocols.xirp.messages import TOO_LARGE, MessageError

_LOGGER = logging.getLogger(__name__)

MAX_BUFFERED = 1024 * 1024
"""Bytes waiting to be sent to a peer beyond which the peer is deemed stuck and dropped."""

_HEADER_SIZE = HEADER.size
_unpack_from = HEADER.unpack_from


class ConnectionLost(ProtocolConnectionError):
    """The peer closed the connection, or it broke."""


class Receiver(Protocol):
    """What a :class:`FrameLink` reports to, all on the event loop."""

    def connection_made(self) -> None:
        """The connection is up."""

    def frame_received(self, payload: bytes) -> None:
        """One complete frame's document arrived."""

    def frame_refused(self, error: MessageError) -> None:
        """A frame longer than allowed was announced; nothing after it will be read."""

    def connection_ended(self, reason: ConnectionLost) -> None:
        """The connection ended (called once, whoever ended it)."""


class FrameLink(asyncio.Protocol):
    """One TCP connection carrying XIRP frames, reporting to a :class:`Receiver`."""

    def __init__(self, receiver: Receiver, max_frame: int) -> None:
        self.receiver = receiver
        self.max_frame = max_frame
        self.peer = "peer"
        """The peer's address, ``HOST:PORT``, for messages (known once connected)."""
        self.source = "message from peer"
        """How messages name a frame's origin: ``message from HOST:PORT``."""
        self._transport: asyncio.Transport | None = None
        self._buffer = bytearray()
        self._refused = False
        self.ended: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        """Done once the connection has ended."""

    # ------------------------------------------------------------ asyncio.Protocol

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        """asyncio: the connection is up."""
        self._transport = cast(asyncio.Transport, transport)
        peer = transport.get_extra_info("peername")
        self.peer = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)
        self.source = f"message from {self.peer}"
        self.receiver.connection_made()

    def data_received(self, data: bytes) -> None:
        """asyncio: bytes arrived; pass on every frame they complete."""
        if self._refused:
            return
        buffer = self._buffer
        if not buffer and len(data) >= _HEADER_SIZE:  # the usual case: whole frames in one segment
            (length,) = _unpack_from(data)
            if len(data) == _HEADER_SIZE + length and length <= self.max_frame:
                self.receiver.frame_received(data[_HEADER_SIZE:])
                return
        buffer += data
        while len(buffer) >= _HEADER_SIZE and not self._refused and not self.closing:
            (length,) = _unpack_from(buffer)
            if length > self.max_frame:
                self._refuse(length)
                return
            end = _HEADER_SIZE + length
            if len(buffer) < end:
                return
            payload = bytes(buffer[_HEADER_SIZE:end])
            del buffer[:end]
            self.receiver.frame_received(payload)

    def _refuse(self, length: int) -> None:
        self._refused = True
        self._buffer.clear()
        self.receiver.frame_refused(
            MessageError(
                f"frame from {self.peer} announces {length} bytes; at most {self.max_frame} are accepted", TOO_LARGE
            )
        )

    def eof_received(self) -> bool:
        """asyncio: the peer will send no more; close our side too."""
        return False

    def connection_lost(self, exc: Exception | None) -> None:
        """asyncio: the connection ended."""
        if exc is None:
            reason = ConnectionLost(f"{self.peer} closed the connection")
        else:
            reason = ConnectionLost(f"connection to {self.peer} broke ({getattr(exc, 'strerror', None) or exc})")
            reason.__cause__ = exc
        if self._buffer:
            reason = ConnectionLost(f"{reason} in the middle of a frame ({len(self._buffer)} bytes unread)")
        self._buffer.clear()
        if not self.ended.done():
            self.ended.set_result(None)
        self.receiver.connection_ended(reason)

    # ------------------------------------------------------------ for the owner

    @property
    def closing(self) -> bool:
        """Whether the connection is closed or being closed (or not yet made)."""
        return self._transport is None or self._transport.is_closing()

    def send(self, data: bytes) -> bool:
        """Queue one frame (header included); ``False`` if the connection is closing or the peer is stuck."""
        transport = self._transport
        if transport is None or transport.is_closing():
            return False
        transport.write(data)
        if transport.get_write_buffer_size() > MAX_BUFFERED:
            _LOGGER.warning(
                "%s takes nothing (over %d bytes waiting); dropping the connection", self.peer, MAX_BUFFERED
            )
            transport.abort()
            return False
        return True

    def pause(self, paused: bool) -> None:
        """Stop (or resume) reading from the peer: back-pressure when frames arrive faster than handled."""
        transport = self._transport
        if transport is not None and not transport.is_closing():
            if paused:
                transport.pause_reading()
            else:
                transport.resume_reading()

    def abort(self) -> None:
        """Drop the connection at once, discarding anything not yet sent."""
        if self._transport is not None:
            self._transport.abort()

    def close_soon(self) -> None:
        """Close after sending what is queued, without waiting."""
        if self._transport is not None:
            self._transport.close()

    async def close(self, linger: float = 1.0) -> None:
        """Close after sending what is queued, and wait for the end (abort if it takes over ``linger`` s)."""
        transport = self._transport
        if transport is None:
            return
        transport.close()
        try:
            async with asyncio.timeout(linger):
                await asyncio.shield(self.ended)
        except TimeoutError:
            transport.abort()
            await asyncio.shield(self.ended)
