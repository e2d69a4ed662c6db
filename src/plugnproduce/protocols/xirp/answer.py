"""How a device answers what a controller sends: one frame in, the frames to send back out.

:class:`Responder` decodes a frame and reacts: a request is answered by the
device's handler (``describe`` by the device's files), a ``bye`` ends the
connection, anything malformed or unexpected gets an ``error``. FaultRule rules
(:mod:`~plugnproduce.protocols.xirp.faults`) are applied on the way.

A reaction is synchronous whenever it can be: a plain-function handler is answered
within the call that received the frame. Only a handler that returns an awaitable
(a coroutine function) needs the rest of the reaction to run later; then
:meth:`Responder.react` returns that rest as a coroutine to await.
"""

from __future__ import annotations

import inspect
import logging
from collections.abc import Awaitable, Callable, Coroutine, Mapping
from typing import Any

from plugnproduce.errors import PlugNProduceError
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.xirp.codec import encode_frame, frame
from plugnproduce.protocols.xirp.decoding import decode
from plugnproduce.protocols.xirp.faults import REQUEST_FAULTS, FaultKind, FaultRule, Faults
from plugnproduce.protocols.xirp.messages import (
    BAD_PARAMETER,
    DESCRIBE,
    FAILED,
    UNEXPECTED,
    UNKNOWN_REQUEST,
    Bye,
    ErrorMessage,
    Failure,
    MessageError,
    Request,
    Response,
    Value,
    documents_of,
)
from plugnproduce.protocols.xirp.stream import FrameLink

_LOGGER = logging.getLogger(__name__)

Results = Mapping[str, Value] | None
RequestHandler = Callable[[Request], Results | Awaitable[Results]]
"""``handler(request) -> results``: what the device does on a request (``None``: no results).

A plain function is answered at once; a coroutine function (``async def``) is
awaited, and later requests of the same connection wait for it. Raise
:class:`RequestFailed` to answer with a failure, e.g. ``RequestFailed("closing", NOT_ACCEPTED)``.
"""

Finish = Coroutine[Any, Any, None]
"""The rest of a reaction, when it has to wait for an asynchronous handler."""


class RequestFailed(PlugNProduceError):
    """Raised by a request handler: the response is a failure with this ``code`` and the message as text."""

    def __init__(self, text: str, code: str = FAILED) -> None:
        super().__init__(text)
        self.code = code


class Responder:
    """The device's side of the conversation, shared by all its connections."""

    def __init__(
        self, device: str, handler: RequestHandler | None, files: DeviceFiles | None, faults: Faults, max_frame: int
    ) -> None:
        self.device = device
        self.faults = faults
        self._handler = handler
        self.files = files
        """What ``describe`` answers with (may be replaced while the server runs)."""
        self._max_frame = max_frame

    def react(self, link: FrameLink, data: bytes) -> Finish | None:
        """React to one frame; return the rest of the reaction if it must wait for the handler."""
        try:
            message = decode(data, link.source)
        except MessageError as exc:
            _LOGGER.info("device %s: %s", self.device, exc)
            link.send(encode_frame(ErrorMessage(exc.code, str(exc), exc.ref)))
            return None
        if isinstance(message, Request):
            return self._on_request(link, message)
        if isinstance(message, Bye):
            _LOGGER.debug("device %s: %s said bye (%s)", self.device, link.peer, message.reason)
            link.close_soon()
        elif isinstance(message, ErrorMessage):  # never answered, or two peers could loop
            _LOGGER.warning("device %s: %s reports %s: %s", self.device, link.peer, message.code, message.text)
        else:
            text = f"a {type(message).__name__.lower()} message is not expected from a controller; expected request"
            link.send(encode_frame(ErrorMessage(UNEXPECTED, text)))
        return None

    def _on_request(self, link: FrameLink, request: Request) -> Finish | None:
        fault = self.faults.take(REQUEST_FAULTS, request.name) if self.faults.rules else None
        if fault is not None and fault.kind is FaultKind.DISCONNECT:
            link.abort()
            return None
        if fault is not None and fault.kind is FaultKind.ERROR_RESPONSE:
            link.send(encode_frame(_failed(request, fault.code, fault.text)))
            return None
        if request.name == DESCRIBE:
            self._send(link, self._describe(request), fault)
            return None
        if self._handler is None:
            self._send(link, _failed(request, UNKNOWN_REQUEST, f"device {self.device!r} takes no requests"), fault)
            return None
        try:
            results = self._handler(request)
        except Exception as exc:  # whatever the handler raises is the device's answer: a failure
            self._send(link, self._failure(request, exc), fault)
            return None
        if inspect.isawaitable(results):
            return self._finish(link, request, results, fault)
        self._send(link, Response(request.id, dict(results or {})), fault)
        return None

    async def _finish(
        self, link: FrameLink, request: Request, pending: Awaitable[Results], fault: FaultRule | None
    ) -> None:
        try:
            results = await pending
        except Exception as exc:  # whatever the handler raises is the device's answer: a failure
            response = self._failure(request, exc)
        else:
            response = Response(request.id, dict(results or {}))
        self._send(link, response, fault)

    def _failure(self, request: Request, exc: Exception) -> Response:
        if isinstance(exc, RequestFailed):
            _LOGGER.info("device %s: %s failed (%s): %s", self.device, request.name, exc.code, exc)
            return _failed(request, exc.code, str(exc))
        # A handler bug must become a failure the controller sees, not a lost connection.
        _LOGGER.error("device %s: the handler of %s raised", self.device, request.name, exc_info=exc)
        return _failed(request, FAILED, f"device {self.device!r} failed on {request.name}: {exc}")

    def _describe(self, request: Request) -> Response:
        if self.files is None:
            return _failed(request, UNKNOWN_REQUEST, f"device {self.device!r} serves no description")
        if request.params:
            return _failed(request, BAD_PARAMETER, f"describe takes no parameters; got {', '.join(request.params)}")
        return Response(request.id, documents=documents_of(self.files))

    def _send(self, link: FrameLink, response: Response, fault: FaultRule | None) -> None:
        """Send the response, unless a fault drops it or sends garbage instead."""
        if fault is not None and fault.kind is FaultKind.DROP_RESPONSE:
            return
        if fault is not None and fault.kind is FaultKind.MALFORMED_RESPONSE:
            link.send(frame(fault.payload))
            return
        link.send(self._response_frame(response))

    def _response_frame(self, response: Response) -> bytes:
        """The response as a frame, or a failure saying why the handler's results cannot be sent."""
        try:
            data = encode_frame(response)
        except MessageError as exc:
            _LOGGER.error("device %s: cannot send the results of request %s: %s", self.device, response.id, exc)
            return encode_frame(_failed_id(response.id, FAILED, f"results cannot be sent: {exc}"))
        if len(data) - 4 > self._max_frame:
            text = f"results take {len(data) - 4} bytes; at most {self._max_frame} fit in a frame"
            return encode_frame(_failed_id(response.id, FAILED, text))
        return data


def _failed(request: Request, code: str, text: str) -> Response:
    return _failed_id(request.id, code, text)


def _failed_id(request_id: str, code: str, text: str) -> Response:
    return Response(request_id, failure=Failure(code, text))
