"""The device side of XIRP: :class:`XirpServer` listens, greets, answers requests and pushes events.

Every connection is greeted with a ``hello``. Requests of one connection are
answered one at a time, in order (how, is :mod:`~plugnproduce.protocols.xirp.answer`):
``describe`` from the device's files, any other by the request handler. Events go to every connected
controller. Something malformed, too large or unexpected from a controller is
answered with an ``error`` (a frame too large also closes that connection); no
controller can stop the server or disturb another controller's connection.
"""

from __future__ import annotations

import asyncio
import logging
from collections import deque
from datetime import UTC, datetime

from plugnproduce.errors import ProtocolConnectionError, ProtocolError
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.xirp.answer import Finish, RequestHandler, Responder
from plugnproduce.protocols.xirp.codec import MAX_FRAME, encode_frame, frame
from plugnproduce.protocols.xirp.faults import EVENT_FAULTS, FaultKind, FaultRule, Faults
from plugnproduce.protocols.xirp.messages import (
    DESCRIBE,
    TOO_LARGE,
    Bye,
    ErrorMessage,
    Event,
    Hello,
    MessageError,
    Params,
    Response,
    documents_of,
    format_endpoint,
)
from plugnproduce.protocols.xirp.stream import ConnectionLost, FrameLink

_LOGGER = logging.getLogger(__name__)


class XirpServer:
    """One device served over XIRP on ``host:port`` (port 0: a free port, see :attr:`port`).

    ``handler`` answers requests (without one, every request but ``describe`` fails
    with ``unknown-request``); ``files`` are served to ``describe``; ``faults``
    makes the device misbehave on purpose (see :mod:`~plugnproduce.protocols.xirp.faults`).
    Use as ``async with XirpServer(...) as server:`` or call :meth:`start` and :meth:`stop`.
    """

    def __init__(
        self,
        device: str,
        device_class: str,
        handler: RequestHandler | None = None,
        *,
        label: str | None = None,
        files: DeviceFiles | None = None,
        host: str = "127.0.0.1",
        port: int = 0,
        faults: Faults | None = None,
        max_frame: int = MAX_FRAME,
    ) -> None:
        self.hello = Hello(device, device_class, label, DESCRIBE if files is not None else None)
        """What every connection is greeted with."""
        self.max_frame = max_frame
        self._responder = Responder(device, handler, files, faults if faults is not None else Faults(), max_frame)
        self._host, self._port = host, port
        self._server: asyncio.Server | None = None
        self._hello_frame = b""
        self._connections: set[_Connection] = set()
        self._delayed: set[asyncio.TimerHandle] = set()
        self._seq = 0

    async def __aenter__(self) -> XirpServer:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.stop()

    @property
    def files(self) -> DeviceFiles | None:
        """What ``describe`` answers with; may be replaced while the server runs (e.g. to name its port)."""
        return self._responder.files

    @files.setter
    def files(self, files: DeviceFiles) -> None:
        self._responder.files = files

    @property
    def faults(self) -> Faults:
        """The fault rules consulted on every request and event; add and clear rules while serving."""
        return self._responder.faults

    @property
    def device(self) -> str:
        """The device id."""
        return self.hello.device

    @property
    def address(self) -> tuple[str, int]:
        """The host and port the server listens on."""
        if self._server is None:
            raise ProtocolError(f"device {self.device!r} is not started")
        host, port = self._server.sockets[0].getsockname()[:2]
        return str(host), int(port)

    @property
    def port(self) -> int:
        """The port the server listens on (the free port chosen when started with port 0)."""
        return self.address[1]

    @property
    def endpoint(self) -> str:
        """Where the device listens, as its description's ``pnp:endpoint`` says it: ``xirp://HOST:PORT``."""
        return format_endpoint(*self.address)

    @property
    def connections(self) -> int:
        """How many controllers are connected."""
        return len(self._connections)

    async def start(self) -> None:
        """Check the hello and description can be sent, then listen."""
        if self._server is not None:
            raise ProtocolError(f"device {self.device!r} is already started, at {self.endpoint}")
        self._hello_frame = encode_frame(self.hello)
        if self.files is not None:
            size = len(encode_frame(Response("x" * 64, documents=documents_of(self.files))))
            if size > self.max_frame:
                raise MessageError(
                    f"device {self.device!r}: its description and chart take {size} bytes in a describe "
                    f"response; at most {self.max_frame} fit in a frame",
                    TOO_LARGE,
                )
        loop = asyncio.get_running_loop()
        try:
            self._server = await loop.create_server(lambda: _Connection(self).link, self._host, self._port)
        except OSError as exc:
            raise ProtocolConnectionError(
                f"device {self.device!r}: cannot listen on {self._host}:{self._port} ({exc.strerror or exc})"
            ) from exc
        _LOGGER.debug("device %s listening at %s", self.device, self.endpoint)

    async def stop(self, reason: str = "device stopping") -> None:
        """Say ``bye`` to every controller, close every connection and stop listening. Safe to call twice."""
        server, self._server = self._server, None
        if server is None:
            return
        server.close()
        for handle in self._delayed:
            handle.cancel()
        self._delayed.clear()
        bye = encode_frame(Bye(reason))
        connections = list(self._connections)
        for connection in connections:
            connection.link.send(bye)
        await asyncio.gather(*(c.link.close() for c in connections))
        await _finish(connections)
        await server.wait_closed()

    async def disconnect_all(self) -> int:
        """Abort every connection at once, without ``bye`` (a crash, a pulled cable); keep listening.

        Returns how many connections were dropped.
        """
        connections = list(self._connections)
        for connection in connections:
            connection.link.abort()
        await asyncio.gather(*(c.link.ended for c in connections))
        await _finish(connections)
        return len(connections)

    # ------------------------------------------------------------ events

    def emit(self, name: str, params: Params | None = None) -> Event:
        """Send an event to every connected controller (queued before this returns); return it.

        Events are numbered from 1 across all connections. An event that cannot be
        encoded raises :class:`~plugnproduce.protocols.xirp.messages.MessageError`
        and uses no number.
        """
        if self._server is None:
            raise ProtocolError(f"device {self.device!r} is not started; cannot send event {name!r}")
        event = Event(name, self._seq + 1, datetime.now(UTC), dict(params or {}))
        data = encode_frame(event)
        self._seq = event.seq
        fault = self.faults.take(EVENT_FAULTS, name) if self.faults.rules else None
        if fault is None:
            self._broadcast(data)
        else:
            self._event_fault(fault, data)
        return event

    def _event_fault(self, fault: FaultRule, data: bytes) -> None:
        if fault.kind is FaultKind.DUPLICATE_EVENT:
            self._broadcast(data + data)
        elif fault.kind is FaultKind.DELAY_EVENT:
            self._broadcast_later(fault.delay, data)
        elif fault.kind is FaultKind.MALFORMED_EVENT:
            self._broadcast(frame(fault.payload))
        # DROP_EVENT: nothing is sent

    def _broadcast(self, data: bytes) -> None:
        for connection in list(self._connections):
            connection.link.send(data)

    def _broadcast_later(self, delay: float, data: bytes) -> None:
        def fire() -> None:
            self._delayed.discard(handle)
            self._broadcast(data)

        handle = asyncio.get_running_loop().call_later(delay, fire)
        self._delayed.add(handle)


_PAUSE_AT = 64  # frames waiting to be handled on one connection before reading from it pauses
_RESUME_AT = 16  # ... and resumes


class _Connection:
    """One controller's connection: frames in, answers out, in order.

    A frame is reacted to as soon as it arrives, unless an earlier reaction still
    waits for an asynchronous handler; then it queues, and the connection's task
    works through the queue in order.
    """

    def __init__(self, server: XirpServer) -> None:
        self.server = server
        self.link = FrameLink(self, server.max_frame)
        self.task: asyncio.Task[None] | None = None
        self._frames: deque[bytes] = deque()
        self._finishing: Finish | None = None
        self._busy = False
        self._waiter: asyncio.Future[None] | None = None
        self._ended = False

    def connection_made(self) -> None:
        """Greet the controller, unless the server is stopping."""
        server = self.server
        if server._server is None:
            self.link.abort()
            return
        server._connections.add(self)
        self.link.send(server._hello_frame)
        self.task = asyncio.get_running_loop().create_task(self._work(), name=f"xirp {server.device} {self.link.peer}")
        _LOGGER.debug("device %s: controller %s connected", server.device, self.link.peer)

    def frame_received(self, payload: bytes) -> None:
        """React now, or queue behind a reaction still in progress (pausing reading if far behind)."""
        if not self._busy:
            self._finishing = self.server._responder.react(self.link, payload)
            if self._finishing is None:
                return
            self._busy = True
        else:
            self._frames.append(payload)
            if len(self._frames) == _PAUSE_AT:
                self.link.pause(True)
        self._wake()

    def frame_refused(self, error: MessageError) -> None:
        """A frame too large: say so and close (the rest of the stream cannot be followed)."""
        _LOGGER.info("device %s: %s; closing the connection", self.server.device, error)
        self.link.send(encode_frame(ErrorMessage(error.code, str(error))))
        self.link.close_soon()

    def connection_ended(self, reason: ConnectionLost) -> None:
        """Forget the connection; the task stops, a reaction not yet started is dropped."""
        _LOGGER.debug("device %s: %s", self.server.device, reason)
        self._ended = True
        self.server._connections.discard(self)
        self.discard()
        self._wake()

    def discard(self) -> None:
        """Drop a reaction that was never started (so no coroutine is left un-awaited)."""
        finishing, self._finishing = self._finishing, None
        if finishing is not None:
            finishing.close()

    def _wake(self) -> None:
        waiter = self._waiter
        if waiter is not None and not waiter.done():
            waiter.set_result(None)

    async def _work(self) -> None:
        """Finish reactions that wait for the handler, then those queued behind them, in order."""
        loop = asyncio.get_running_loop()
        try:
            while not self._ended:
                finishing, self._finishing = self._finishing, None
                if finishing is not None:
                    await finishing
                elif self._frames:
                    payload = self._frames.popleft()
                    if len(self._frames) == _RESUME_AT:
                        self.link.pause(False)
                    self._finishing = self.server._responder.react(self.link, payload)
                else:
                    self._busy = False
                    self._waiter = loop.create_future()
                    await self._waiter
        except Exception:  # a bug here must cost one connection, not the device: log it with its traceback
            _LOGGER.exception("device %s: serving %s failed", self.server.device, self.link.peer)
            self.link.abort()


async def _finish(connections: list[_Connection]) -> None:
    """Stop the tasks of connections that have ended."""
    tasks = [c.task for c in connections if c.task is not None]
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
    for connection in connections:
        connection.discard()
