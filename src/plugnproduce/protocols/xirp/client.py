"""The controller side of XIRP: :class:`XirpClient` connects to one device, requests, and receives events.

Every frame the device sends is handled as it arrives (the connection is a
:class:`~plugnproduce.protocols.xirp.stream.FrameLink`): responses complete the
request waiting for them (matched by id), events are handed to the ``on_event``
callback or queued for :meth:`XirpClient.next_event` / :meth:`XirpClient.events`.
When the connection ends (the device leaves, says ``bye``, or the connection
breaks) every waiting request fails with
:class:`~plugnproduce.errors.ProtocolConnectionError` and :attr:`XirpClient.lost`
says why.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator
from typing import Any

from plugnproduce.errors import ProtocolConnectionError, ProtocolError, ProtocolTimeout, RemoteError
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.xirp.codec import MAX_FRAME, encode_frame
from plugnproduce.protocols.xirp.decoding import decode
from plugnproduce.protocols.xirp.inbox import EventCallback, EventInbox, LinkStats
from plugnproduce.protocols.xirp.messages import (
    DESCRIBE,
    STATE,
    STATE_RESULT,
    TOO_LARGE,
    UNEXPECTED,
    VERSION,
    Bye,
    ErrorMessage,
    Event,
    Hello,
    MessageError,
    Params,
    Request,
    Response,
    Value,
    files_from_documents,
    format_endpoint,
    parse_endpoint,
)
from plugnproduce.protocols.xirp.pending import PendingRequests
from plugnproduce.protocols.xirp.stream import ConnectionLost, FrameLink

_LOGGER = logging.getLogger(__name__)

class RemoteFailure(RemoteError):
    """The device answered a request with a failure (or a protocol error naming it)."""

    def __init__(self, message: str, code: str, text: str, request: str) -> None:
        super().__init__(message)
        self.code = code
        """The failure code (``not-accepted``, ``failed``, … or a protocol error code such as ``malformed``)."""
        self.text = text
        """The device's own words."""
        self.request = request
        """The name of the request that failed."""


class XirpClient:
    """A connection to one device. Make one with :meth:`connect`; end it with :meth:`close`.

    ``timeout`` is the default for :meth:`request` and :meth:`next_event`.
    """

    def __init__(
        self, what: str, *, timeout: float, on_event: EventCallback | None, event_buffer: int, max_frame: int
    ) -> None:
        """Not connected yet: use :meth:`connect`."""
        self.timeout = timeout
        self.stats = LinkStats()
        self._link = FrameLink(self, max_frame)
        self._what = what
        self._source = f"message from {what}"
        self._hello: Hello | None = None
        self._greeted: asyncio.Future[Hello] = asyncio.get_running_loop().create_future()
        self._inbox = EventInbox(what, on_event, event_buffer, self.stats)
        self._pending = PendingRequests(what)
        self._closing = False
        self._ended = False
        self._lost: ProtocolConnectionError | None = None

    @classmethod
    async def connect(
        cls,
        host: str,
        port: int,
        *,
        timeout: float = 10.0,
        on_event: EventCallback | None = None,
        event_buffer: int = 1024,
        max_frame: int = MAX_FRAME,
    ) -> XirpClient:
        """Connect and wait for the device's ``hello`` (both within ``timeout`` seconds).

        Events go to ``on_event`` if given, else into a buffer of ``event_buffer``
        events read with :meth:`next_event` (when it is full the oldest is dropped).
        """
        what = f"XIRP device at {format_endpoint(host, port)}"
        client = cls(what, timeout=timeout, on_event=on_event, event_buffer=event_buffer, max_frame=max_frame)
        loop = asyncio.get_running_loop()
        try:
            async with asyncio.timeout(timeout):
                await loop.create_connection(lambda: client._link, host, port)
                await client._greeted
        except BaseException as exc:
            client._greeted.cancel()
            client._link.abort()
            await client._link.close()
            if isinstance(exc, TimeoutError):
                raise ProtocolTimeout(f"{what}: no connection and hello within {timeout:g} s") from exc
            if isinstance(exc, OSError):
                raise ProtocolConnectionError(f"{what}: cannot connect ({exc.strerror or exc})") from exc
            raise
        return client

    @classmethod
    async def connect_endpoint(
        cls,
        endpoint: str,
        *,
        timeout: float = 10.0,
        on_event: EventCallback | None = None,
        event_buffer: int = 1024,
        max_frame: int = MAX_FRAME,
    ) -> XirpClient:
        """:meth:`connect` to ``xirp://HOST:PORT`` (a device's ``pnp:endpoint``)."""
        host, port = parse_endpoint(endpoint)
        return await cls.connect(
            host, port, timeout=timeout, on_event=on_event, event_buffer=event_buffer, max_frame=max_frame
        )

    async def __aenter__(self) -> XirpClient:
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.close()

    @property
    def hello(self) -> Hello:
        """The device's greeting: its id, class, label and describe request."""
        if self._hello is None:
            raise ProtocolError(f"{self._what}: not connected yet (use XirpClient.connect)")
        return self._hello

    @property
    def device(self) -> str:
        """The device id from its hello."""
        return self.hello.device

    @property
    def connected(self) -> bool:
        """Whether the connection is up (not lost, not closed)."""
        return self._lost is None and not self._closing

    @property
    def lost(self) -> ProtocolConnectionError | None:
        """Why the connection ended (``None`` while it is up or after :meth:`close`)."""
        return self._lost

    async def wait_closed(self) -> None:
        """Return once the connection has ended, whoever ended it."""
        await asyncio.shield(self._link.ended)

    # ------------------------------------------------------------ requests

    async def request(
        self, name: str, params: Params | None = None, *, timeout: float | None = None
    ) -> dict[str, Value]:
        """Send request ``name`` with typed ``params`` and return the results of its response.

        :class:`RemoteFailure` if the device answers with a failure,
        :class:`~plugnproduce.errors.ProtocolTimeout` if no response comes within
        ``timeout`` seconds (default :attr:`timeout`; a late response is ignored),
        :class:`~plugnproduce.errors.ProtocolConnectionError` if the connection is
        or gets lost, :class:`~plugnproduce.protocols.xirp.messages.MessageError`
        if a parameter cannot be sent (before anything is sent).
        """
        response = await self._exchange(name, params or {}, timeout)
        if response.failure is not None:
            code, text = response.failure.code, response.failure.text
            raise RemoteFailure(f"request {name} to {self._what} failed: {code}: {text}", code, text, name)
        return dict(response.results)

    async def describe(self, *, timeout: float | None = None) -> DeviceFiles:
        """Fetch the device's Turtle description and SCXML chart (the ``describe`` request)."""
        if self.hello.describe is None:
            raise ProtocolError(f"{self._what} serves no description (its hello names no describe request)")
        response = await self._exchange(self.hello.describe, {}, timeout)
        if response.failure is not None:
            code, text = response.failure.code, response.failure.text
            raise RemoteFailure(f"{DESCRIBE} of {self._what} failed: {code}: {text}", code, text, DESCRIBE)
        return files_from_documents(response.documents, f"{DESCRIBE} of {self._what}")

    async def state(self, *, timeout: float | None = None) -> str:
        """The device's current state: the id of its device state chart's state (the ``state`` request)."""
        return (await self.report(timeout=timeout))[0]

    async def report(self, *, timeout: float | None = None) -> tuple[str, dict[str, Any]]:
        """The device's current state and the values it reports with it (its other results: the quantities its
        chart's ``<data pnp:quantity=...>`` hold, by quantity name), from one ``state`` request."""
        results = await self.request(STATE, timeout=timeout)
        value = results.pop(STATE_RESULT, None)
        if not isinstance(value, str) or not value:
            raise ProtocolError(f"{STATE} of {self._what}: expected a string result {STATE_RESULT}; got "
                                f"{sorted(results) or 'none'}")
        return value, results

    async def _exchange(self, name: str, params: Params, timeout: float | None) -> Response:
        if self._lost is not None or self._closing:
            raise ProtocolConnectionError(f"request {name} to {self._what}: {self._lost or 'the connection is closed'}")
        request_id = self._pending.next_id()
        data = encode_frame(Request(request_id, name, params))
        if len(data) - 4 > self._link.max_frame:
            size, most = len(data) - 4, self._link.max_frame
            raise MessageError(f"request {name} to {self._what} takes {size} bytes; at most {most} fit", TOO_LARGE)
        future = self._pending.wait(request_id, name, self.timeout if timeout is None else timeout)
        try:
            self._link.send(data)
            return await future
        except ConnectionLost as exc:
            raise ProtocolConnectionError(f"request {name}: {exc}") from exc
        finally:
            self._pending.done(request_id)

    # ------------------------------------------------------------ events

    async def next_event(self, timeout: float | None = None) -> Event:
        """The next event (in arrival order); :class:`~plugnproduce.errors.ProtocolTimeout` if none comes in time.

        Events that arrived before the connection ended are still returned; after
        them, :class:`~plugnproduce.errors.ProtocolConnectionError`.
        """
        limit = self.timeout if timeout is None else timeout
        try:
            async with asyncio.timeout(limit):
                return await self._inbox.get()
        except TimeoutError as exc:
            raise ProtocolTimeout(f"waiting for an event from {self._what}: none within {limit:g} s") from exc

    async def events(self) -> AsyncIterator[Event]:
        """Every event, as it arrives, until :meth:`close`; raises ProtocolConnectionError if the connection is lost."""
        while True:
            try:
                yield await self._inbox.get()
            except ProtocolConnectionError:
                if self._lost is None:  # closed by us: the end of the events, not an error
                    return
                raise

    # ------------------------------------------------------------ reading (FrameLink's receiver)

    def connection_made(self) -> None:
        """The connection is up; the device speaks first."""

    def frame_received(self, payload: bytes) -> None:
        """Handle one frame from the device: its hello first, then anything."""
        if self._hello is None:
            self._greet(payload)
            return
        reason = self._on_frame(payload)
        if reason is not None:
            self._end(reason)
            self._link.close_soon()

    def frame_refused(self, error: MessageError) -> None:
        """A frame too large: say so and close (the rest of the stream cannot be followed)."""
        self._link.send(encode_frame(ErrorMessage(error.code, str(error))))
        self._end(ProtocolConnectionError(f"{self._what}: {error}; connection closed"))
        self._link.close_soon()

    def connection_ended(self, reason: ConnectionLost) -> None:
        """The connection ended: fail every waiting request, wake every event reader."""
        self._end(ProtocolConnectionError(f"{self._what}: connection lost ({reason})"))

    def _greet(self, payload: bytes) -> None:
        try:
            message = decode(payload, f"first message of {self._what}")
            if not isinstance(message, Hello):
                raise ProtocolError(f"{self._what}: first message is a {type(message).__name__}; expected hello")
            if message.version != VERSION:
                raise ProtocolError(f"{self._what}: speaks XIRP version {message.version}; expected {VERSION}")
        except ProtocolError as exc:
            if not self._greeted.done():
                self._greeted.set_exception(exc)
            self._link.abort()
            return
        self._hello = message
        self._what = self._inbox.what = self._pending.what = f"device {message.device!r} at {self._link.peer}"
        self._source = f"message from {self._what}"
        if not self._greeted.done():
            self._greeted.set_result(message)

    def _end(self, reason: ProtocolConnectionError) -> None:
        if self._ended:
            return
        self._ended = True
        if not self._closing:
            self._lost = reason
            _LOGGER.info("%s", reason)
        lost = ConnectionLost(str(self._lost or "the connection was closed by the controller"))
        self._pending.fail_all(lost)
        if not self._greeted.done():
            self._greeted.set_exception(reason)
        self._inbox.end(str(self._lost or "the connection is closed"))

    def _on_frame(self, data: bytes) -> ProtocolConnectionError | None:
        """Handle one frame; a returned error ends the connection with that reason."""
        try:
            message = decode(data, self._source)
        except MessageError as exc:
            self.stats.malformed += 1
            self._inbox.log.log(logging.WARNING, "%s", exc)
            self.stats.tell(str(exc))
            self._link.send(encode_frame(ErrorMessage(exc.code, str(exc), exc.ref)))
            return None
        if isinstance(message, Response):
            waiting = self._pending.get(message.id)
            if waiting is not None and not waiting.future.done():
                waiting.future.set_result(message)
            else:
                self._inbox.log.log(logging.INFO, "%s: response to request %s, which no one waits for; ignored",
                                    self._what, message.id)
        elif isinstance(message, Event):
            self._inbox.put(message)
        elif isinstance(message, ErrorMessage):
            self._on_error(message)
        elif isinstance(message, Bye):
            return ProtocolConnectionError(f"{self._what} said bye ({message.reason or 'no reason given'})")
        else:
            text = f"a {type(message).__name__.lower()} message is not expected from a device now"
            self._link.send(encode_frame(ErrorMessage(UNEXPECTED, text)))
        return None

    def _on_error(self, error: ErrorMessage) -> None:
        waiting = self._pending.get(error.ref) if error.ref is not None else None
        if waiting is not None and not waiting.future.done():
            message = f"{self._what} refused request {error.ref} as {error.code}: {error.text}"
            waiting.future.set_exception(RemoteFailure(message, error.code, error.text, waiting.name))
            return
        self.stats.errors.append(error)
        self.stats.reported += 1
        self._inbox.log.log(logging.WARNING, "%s reports %s: %s", self._what, error.code, error.text[:200])
        self.stats.tell(f"{self._what} reports {error.code}: {error.text}")

    async def close(self) -> None:
        """Say ``bye`` and close; waiting requests fail with ProtocolConnectionError. Safe to call twice."""
        if not self._closing:
            self._closing = True
            if self._lost is None:
                self._link.send(encode_frame(Bye()))
        await self._link.close()
