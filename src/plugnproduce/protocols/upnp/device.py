"""The device side: publish a Plug'n'Produce device as a UPnP root device.

:class:`UpnpDeviceServer` takes async-upnp-client server classes built from a
:class:`~plugnproduce.protocols.upnp.spec.ServiceSpec` (:mod:`plugnproduce.protocols.upnp.serverclasses`),
serves them over HTTP with the library's own SOAP and GENA handlers, answers SSDP
searches and announces ``ssdp:alive`` on start and ``ssdp:byebye`` on stop.

It does not use the library's ``UpnpServer`` wrapper, for two reasons verified
with async-upnp-client 0.49: ``UpnpServer`` cannot take port 0 (``http_port=None``
binds aiohttp's default 8080 and advertises ``http://host:None/...``), and its
stop leaves the search responder's reply socket open (a ResourceWarning). The
same library parts are assembled here instead, on a socket bound before the
device is built, and stopped completely.
"""

from __future__ import annotations

import asyncio
import json
import logging
import socket
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from functools import partial
from typing import Any, cast

from aiohttp import web
from async_upnp_client.aiohttp import AiohttpRequester
from async_upnp_client.client import UpnpStateVariable
from async_upnp_client.exceptions import UpnpActionError, UpnpActionErrorCode, UpnpError, UpnpValueError
from async_upnp_client.server import (
    SsdpAdvertisementAnnouncer,
    UpnpServerDevice,
    UpnpServerService,
    UpnpXmlSerializer,
    subscribe_handler,
    to_xml,
    unsubscribe_handler,
)

from plugnproduce.errors import PlugNProduceError, ProtocolConnectionError, ProtocolError
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.upnp.boundary import LOOPBACK, SsdpNetwork, reason
from plugnproduce.protocols.upnp.serverclasses import (
    CONTENT_TYPES,
    CONTROL_PATH,
    DESCRIPTION_PATH,
    EVENT_PATH,
    FILES_PATH,
    REFUSAL,
    SCPD_PATH,
    ActionHandler,
    SearchResponder,
    control_route,
    device_class,
    service_class,
)
from plugnproduce.protocols.upnp.spec import (
    PNP_XML_NS,
    SERVICE_TYPE,
    ServiceSpec,
    payload_variable,
    udn_for,
)

_LOGGER = logging.getLogger(__name__)


class ActionFailed(PlugNProduceError):
    """Raised by an action handler to refuse or fail an action; the caller gets a UPnP error ``code``.

    Use 501 (Action Failed) for a failure, a code from 700 to 799 for an
    action-specific refusal, e.g. :data:`NOT_ACCEPTED_NOW` when the device's state
    chart does not wait for this request in its current state. The message goes to the
    caller as the error's description (at most
    :data:`~plugnproduce.protocols.upnp.serverclasses.DESCRIPTION_CHARS` characters).
    """

    def __init__(self, message: str, code: int = UpnpActionErrorCode.ACTION_FAILED.value) -> None:
        super().__init__(message)
        self.code = code


NOT_ACCEPTED_NOW = 701
"""UPnP error code: the request is not accepted in the device's current state."""
ARGUMENT_VALUE_INVALID = 600
"""UPnP error code (Argument Value Invalid): an argument is not its datatype's lexical form."""

class UpnpDeviceServer:
    """One device published over UPnP: description, SOAP actions, GENA events, SSDP, own files.

    Action invocations go to ``handler(name, arguments)``, whose mapping of
    out-arguments is the answer (chart-derived actions have one, ``Result``).
    Evented variables are changed with :meth:`set_variable` or, for event
    counters, :meth:`emit`; each change is sent to every subscriber before the
    call returns. Use as ``async with UpnpDeviceServer(...) as server:`` or call
    :meth:`start` and :meth:`stop`.
    """

    def __init__(
        self,
        device_id: str,
        friendly_name: str,
        device_type: str,
        service: ServiceSpec,
        handler: ActionHandler,
        *,
        files: DeviceFiles | None = None,
        network: SsdpNetwork = LOOPBACK,
        udn: str | None = None,
    ) -> None:
        self.device_id = device_id
        self.friendly_name = friendly_name
        self.device_type = device_type
        self.spec = service
        self.files = files
        self.network = network
        self.udn = udn or udn_for(device_id)
        self._handler = handler
        self._device: UpnpServerDevice | None = None
        self._runner: web.AppRunner | None = None
        self._responder: SearchResponder | None = None
        self._announcer: SsdpAdvertisementAnnouncer | None = None
        self._send_lock = asyncio.Lock()
        self.location: str | None = None
        """The URL of the UPnP device description, once started."""

    async def __aenter__(self) -> UpnpDeviceServer:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.stop()

    @property
    def _service(self) -> UpnpServerService:
        if self._device is None:
            raise ProtocolError(f"device {self.device_id!r} is not started")
        return cast(UpnpServerService, self._device.service(SERVICE_TYPE))

    async def start(self) -> None:
        """Serve HTTP on a free port of the network's interface, then answer searches and announce alive."""
        if self._runner is not None:
            raise ProtocolError(f"device {self.device_id!r} is already started, at {self.location}")
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            sock.bind((self.network.interface, 0))
        except OSError as exc:
            sock.close()
            raise ProtocolConnectionError(
                f"device {self.device_id!r}: cannot bind HTTP to {self.network.interface} ({exc.strerror})"
            ) from exc
        base_uri = f"http://{self.network.interface}:{sock.getsockname()[1]}"
        service = service_class(self.spec, self._dispatch)
        device = self._device = device_class(self.udn, self.device_type, self.friendly_name, service)(
            AiohttpRequester(), base_uri)
        self.location = base_uri + DESCRIPTION_PATH
        self._runner = web.AppRunner(self._app(), shutdown_timeout=2.0)
        await self._runner.setup()
        await web.SockSite(self._runner, sock).start()
        try:
            await self._start_ssdp(device)
        except (OSError, UpnpError) as exc:
            await self.stop()
            raise ProtocolConnectionError(
                f"device {self.device_id!r}: cannot start SSDP on {self.network.interface} for "
                f"{self.network.group}:{self.network.port} ({reason(exc)}); multicast must be possible "
                "on that interface"
            ) from exc
        _LOGGER.debug("device %s published at %s", self.device_id, self.location)

    async def _start_ssdp(self, device: UpnpServerDevice) -> None:
        source, target = self.network.source, self.network.target
        responder = SearchResponder(device, source=source, target=target)
        await responder.async_start()
        self._responder = responder
        announcer = SsdpAdvertisementAnnouncer(device, source=source, target=target)
        await announcer.async_start()
        self._announcer = announcer

    async def stop(self) -> None:
        """Announce byebye, stop answering searches and close the HTTP server. Safe to call twice."""
        announcer, self._announcer = self._announcer, None
        responder, self._responder = self._responder, None
        runner, self._runner = self._runner, None
        if announcer is not None:
            await announcer.async_stop()
        if responder is not None:
            await responder.async_stop()
        if runner is not None:
            await runner.cleanup()
        self._device = None

    def _app(self) -> web.Application:
        service = self._service
        app = web.Application()
        app.router.add_get(DESCRIPTION_PATH, self._description)
        app.router.add_get(SCPD_PATH, partial(to_xml, service))
        app.router.add_post(CONTROL_PATH, partial(control_route, service))
        app.router.add_route("SUBSCRIBE", EVENT_PATH, partial(self._subscribe, service))
        app.router.add_route("UNSUBSCRIBE", EVENT_PATH, partial(unsubscribe_handler, service))
        if self.files is not None:
            app.router.add_get(FILES_PATH + "{name}", self._file)
        return app

    async def _subscribe(self, service: UpnpServerService, request: web.Request) -> web.StreamResponse:
        """The library's SUBSCRIBE handler, run while no change is being sent.

        The library sends a new subscriber its initial event and only then adds it
        to the subscribers; a change sent in between would be lost to it. Holding
        the send lock makes such a change wait, and reach the new subscriber too.
        """
        async with self._send_lock:
            return await subscribe_handler(service, request)

    async def _description(self, _request: web.Request) -> web.Response:
        """The library's device description, plus vendor elements naming the device's own files."""
        if self._device is None:
            raise web.HTTPServiceUnavailable()
        root = UpnpXmlSerializer.to_xml(self._device)
        device_el = root.find("device")
        if self.files is not None and device_el is not None:
            for tag, name in (("descriptionURL", self.files.description_name), ("chartURL", self.files.chart_name)):
                ET.SubElement(device_el, f"pnp:{tag}", {"xmlns:pnp": PNP_XML_NS}).text = FILES_PATH + name
        body = ET.tostring(root, encoding="utf-8", xml_declaration=True)
        return web.Response(body=body, content_type="text/xml", charset="utf-8")

    async def _file(self, request: web.Request) -> web.Response:
        files = self.files
        name = request.match_info["name"]
        texts = {files.description_name: files.description, files.chart_name: files.chart} if files else {}
        if name not in texts:
            raise web.HTTPNotFound()
        suffix = name[name.rfind(".") :]
        return web.Response(text=texts[name], content_type=CONTENT_TYPES.get(suffix, "text/plain"), charset="utf-8")

    async def _dispatch(self, action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        """Run the handler; turn its refusal or failure into a UPnP error the library can answer."""
        spec = self.spec.action(action)
        try:
            result = dict(await self._handler(action, dict(arguments)))
        except ActionFailed as exc:
            _LOGGER.info("device %s: action %s failed (%s): %s", self.device_id, action, exc.code, exc)
            REFUSAL.set(str(exc))
            raise UpnpActionError(error_code=exc.code, error_desc=str(exc)) from exc
        except Exception as exc:  # a handler bug must not become a bare HTTP 500
            _LOGGER.exception("device %s: handler of action %s raised", self.device_id, action)
            raise UpnpActionError(error_code=UpnpActionErrorCode.ACTION_FAILED.value, error_desc=str(exc)) from exc
        expected = {a.name for a in spec.outputs}
        if set(result) != expected:
            _LOGGER.error("device %s: action %s returned %s; expected %s", self.device_id, action, result, expected)
            raise UpnpActionError(error_code=UpnpActionErrorCode.ACTION_FAILED.value, error_desc="bad result")
        return result

    def _variable(self, name: str) -> UpnpStateVariable[Any]:
        try:
            self.spec.variable(name)
        except KeyError:
            known = ", ".join(v.name for v in self.spec.variables) or "none"
            raise ProtocolError(
                f"device {self.device_id!r} has no evented state variable {name!r}; it has: {known}"
            ) from None
        return self._service.state_variable(name)

    def value(self, name: str) -> Any:
        """The current value of an evented state variable."""
        return self._variable(name).value

    async def set_variable(self, name: str, value: Any) -> None:
        """Change an evented state variable and send the change to every subscriber (GENA NOTIFY).

        A value outside the variable's type or allowed values raises
        :class:`~plugnproduce.errors.ProtocolError` naming the allowed values.
        """
        if self._store(name, value):
            await self._send_events()

    def _store(self, name: str, value: Any) -> bool:
        """Change a state variable without notifying; whether its value changed."""
        variable = self._variable(name)
        previous = variable.value
        try:
            # The base-class setter validates and stores without the library's own
            # fire-and-forget notification task; the change is sent below, awaited.
            UpnpStateVariable.value.fset(variable, value)  # type: ignore[attr-defined]
        except UpnpValueError as exc:
            allowed = self.spec.variable(name).allowed_values
            expected = f"one of {', '.join(allowed)}" if allowed else f"a {variable.data_type}"
            raise ProtocolError(
                f"device {self.device_id!r}: value {value!r} for state variable {name!r} is refused; "
                f"expected {expected}"
            ) from exc
        return bool(variable.value != previous)

    async def emit(self, event: str, payload: Mapping[str, Any] | None = None) -> int:
        """Count one occurrence of a chart event (a ``ui4`` counter variable) and notify; return the new count.

        The values the event carries (``payload``) go as JSON into its ``EVENT__NAME`` variables,
        sent in the same notification as the counter.
        """
        for name, value in (payload or {}).items():
            self._store(payload_variable(event, name), json.dumps(value))
        count = int(self.value(event) or 0) + 1
        await self.set_variable(event, count)
        return count

    async def _send_events(self) -> None:
        async with self._send_lock:
            try:
                await self._service.async_send_events()
            except (UpnpError, OSError) as exc:  # one unreachable subscriber must not stop the device
                _LOGGER.warning("device %s: sending an event failed: %s", self.device_id, reason(exc))
