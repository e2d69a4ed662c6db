"""The controller side of one device: SOAP actions, GENA events, the device's own files.

:class:`UpnpDeviceClient` reads a device's UPnP description and talks to it
through async-upnp-client only, and only with the host the device was discovered
at (see :mod:`plugnproduce.protocols.upnp.boundary`).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Mapping, Sequence
from datetime import timedelta
from typing import TYPE_CHECKING, Any, NamedTuple

from async_upnp_client.aiohttp import AiohttpNotifyServer
from async_upnp_client.client import UpnpAction, UpnpDevice, UpnpService, UpnpStateVariable
from async_upnp_client.client_factory import UpnpFactory
from async_upnp_client.const import HttpRequest
from async_upnp_client.event_handler import default_on_pre_notify
from async_upnp_client.exceptions import UpnpConnectionTimeoutError, UpnpValueError
from async_upnp_client.utils import get_local_ip

from plugnproduce.errors import ProtocolError, ProtocolTimeout, RemoteError
from plugnproduce.protocols.upnp.boundary import (
    ChangeSignal,
    NoRedirectRequester,
    TrustedRequester,
    check_trusted,
    reason,
    resolve_trusted,
    upnp_errors,
)
from plugnproduce.protocols.upnp.spec import PNP_XML_NS, SERVICE_TYPE, RemoteFiles
from plugnproduce.safeio import MAX_BYTES

if TYPE_CHECKING:
    from plugnproduce.protocols.upnp.discovery import FoundDevice

_LOGGER = logging.getLogger(__name__)
_EMPTY_PROPERTYSET = '<e:propertyset xmlns:e="urn:schemas-upnp-org:event-1-0"/>'

TIMEOUT = 10.0
"""Seconds each exchange with a device may take, unless the client or a call is given another bound."""


class VariableChange(NamedTuple):
    """An evented state variable of a device took a new value (after a GENA NOTIFY)."""

    variable: str
    value: Any


async def load_device(location: str, requester: TrustedRequester, what: str, timeout: float) -> UpnpDevice:
    """Read a UPnP device description (and its service descriptions) through ``requester``."""
    check_trusted(location, requester.trusted_host, what)
    with upnp_errors(f"reading the description of {what}"):
        try:
            async with asyncio.timeout(timeout):
                return await UpnpFactory(requester).async_create_device(location)
        except (KeyError, ValueError) as exc:  # a malformed description (defusedxml refusals are ValueErrors)
            raise RemoteError(f"reading the description of {what}: malformed description ({reason(exc)})") from exc
        except (UpnpConnectionTimeoutError, TimeoutError) as exc:  # the wait a user may lengthen: say how long
            raise ProtocolTimeout(f"reading the description of {what}: no answer within {timeout:g} s") from exc


class UpnpDeviceClient:
    """Talk to one Plug'n'Produce device: ``await client.call("MoveTo", Pose="...")``.

    Open with :meth:`connect` (a description URL and the host it was discovered
    at) or :meth:`from_found`; close with :meth:`close` or ``async with``.
    ``timeout`` bounds every exchange unless a call gives its own.
    """

    def __init__(self, device: UpnpDevice, requester: TrustedRequester, timeout: float) -> None:
        if not device.has_service(SERVICE_TYPE):
            raise RemoteError(f"device {device.friendly_name!r} at {device.device_url} has no service {SERVICE_TYPE}")
        self._device = device
        self._service: UpnpService = device.service(SERVICE_TYPE)
        self._requester = requester
        self.timeout = timeout
        self._notify: AiohttpNotifyServer | None = None
        self._renewal: asyncio.Task[None] | None = None
        self._on_change: Callable[[str, Any], None] | None = None
        self._last_seq: dict[str, int] = {}
        self._baseline = False
        self._values: dict[str, Any] = {}
        self._changed = ChangeSignal()
        self.events: asyncio.Queue[VariableChange] = asyncio.Queue()
        """Changes of evented variables after :meth:`subscribe`, when no ``on_change`` callback was given."""

    @classmethod
    async def connect(cls, location: str, trusted_host: str, *, timeout: float = TIMEOUT) -> UpnpDeviceClient:
        """Read the device description at ``location``; every URL must be on ``trusted_host``."""
        what = f"device at {location}"
        requester = TrustedRequester(NoRedirectRequester(timeout, MAX_BYTES), trusted_host, what)
        return cls(await load_device(location, requester, what, timeout), requester, timeout)

    @classmethod
    async def from_found(cls, found: FoundDevice, *, timeout: float = TIMEOUT) -> UpnpDeviceClient:
        """Connect to a discovered device, trusting only the address it answered from."""
        client = await cls.connect(found.location, found.source_host, timeout=timeout)
        if client.udn.lower() != found.udn.lower():
            raise RemoteError(f"device at {found.location} describes itself as {client.udn}; discovered as {found.udn}")
        return client

    async def __aenter__(self) -> UpnpDeviceClient:
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.close()

    @property
    def udn(self) -> str:
        """The device's unique device name (``uuid:...``)."""
        return self._device.udn

    @property
    def device_type(self) -> str:
        """The device's UPnP device type."""
        return self._device.device_type

    @property
    def friendly_name(self) -> str:
        """The device's friendly name."""
        return self._device.friendly_name

    @property
    def location(self) -> str:
        """The URL of the device's UPnP description."""
        return self._device.device_url

    @property
    def trusted_host(self) -> str:
        """The one host this client talks to."""
        return self._requester.trusted_host

    @property
    def actions(self) -> dict[str, tuple[str, ...]]:
        """Each action's name and the names of its in-arguments."""
        return {n: tuple(a.name for a in act.in_arguments()) for n, act in self._service.actions.items()}

    @property
    def variables(self) -> tuple[str, ...]:
        """The names of the evented state variables."""
        return tuple(v.name for v in self._service.state_variables.values() if v.send_events)

    @property
    def values(self) -> Mapping[str, Any]:
        """The last value received for each evented variable (empty before :meth:`subscribe`)."""
        return dict(self._values)

    def _what(self, action: str | None = None) -> str:
        device = f"device {self.friendly_name!r} at {self.location}"
        return f"{action} on {device}" if action else device

    async def call(self, action: str, /, **arguments: Any) -> dict[str, Any]:
        """Invoke ``action`` with keyword arguments; return its out-arguments."""
        return await self.invoke(action, arguments)

    async def invoke(
        self, action: str, arguments: Mapping[str, Any], *, timeout: float | None = None
    ) -> dict[str, Any]:
        """Invoke ``action``; arguments are Python values or their UPnP lexical form (``"40"`` for an ``i4``).

        An unknown action, a missing or unknown argument, or a value outside the
        argument's type or allowed values is refused with
        :class:`~plugnproduce.errors.ProtocolError` before anything is sent; a
        device's refusal is a :class:`~plugnproduce.errors.RemoteError`.
        """
        upnp_action = self._action(action)
        values = self._checked_arguments(upnp_action, arguments)
        with upnp_errors(self._what(action)):
            async with asyncio.timeout(self.timeout if timeout is None else timeout):
                return dict(await upnp_action.async_call(**values))

    def _action(self, name: str) -> UpnpAction:
        if not self._service.has_action(name):
            known = ", ".join(sorted(self._service.actions)) or "none"
            raise ProtocolError(f"{self._what()} has no action {name!r}; it has: {known}")
        return self._service.action(name)

    def _checked_arguments(self, action: UpnpAction, arguments: Mapping[str, Any]) -> dict[str, Any]:
        expected = [a.name for a in action.in_arguments()]
        missing = [n for n in expected if n not in arguments]
        unknown = [n for n in arguments if n not in expected]
        if missing or unknown:
            raise ProtocolError(
                f"{self._what(action.name)}: arguments {sorted(arguments)} do not match; expected "
                f"{expected or 'none'} (missing: {missing or 'none'}, unknown: {unknown or 'none'})"
            )
        return {
            a.name: _checked_value(a.related_state_variable, a.name, arguments[a.name], self._what(action.name))
            for a in action.in_arguments()
        }

    async def subscribe(self, on_change: Callable[[str, Any], None] | None = None, *, seconds: int = 1800) -> None:
        """Subscribe to the device's evented variables (GENA).

        Returns once the device's initial event has arrived; its values are the
        baseline (:attr:`values`), not changes. Each later change is passed to
        ``on_change(variable, value)`` (a plain function, run soon after on the
        event loop) or, without one, put on :attr:`events`. The subscription is
        renewed before its ``seconds`` run out.
        """
        if self._notify is not None:
            raise ProtocolError(f"{self._what()}: already subscribed")
        self._on_change = on_change
        self._last_seq, self._baseline = {}, False
        loop = asyncio.get_running_loop()
        notify = AiohttpNotifyServer(self._requester, source=(get_local_ip(self.location), 0), loop=loop)
        with upnp_errors(f"starting the event listener for {self._what()}"):
            await notify.async_start_server()
        self._notify = notify
        notify.event_handler.on_pre_notify = self._pre_notify
        self._service.on_event = self._on_event
        try:
            with upnp_errors(f"subscribing to {self._what()}"):
                async with asyncio.timeout(self.timeout):
                    await notify.event_handler.async_subscribe(self._service, timeout=timedelta(seconds=seconds))
            await self._changed.wait_for(
                lambda: True if self._baseline else None, self.timeout, f"initial event of {self._what()}"
            )
        except ProtocolError:
            await self._stop_notify()
            raise
        self._renewal = asyncio.create_task(self._renew(seconds))

    def _pre_notify(self, request: HttpRequest) -> HttpRequest:
        """Neutralise a NOTIFY older than one already applied (GENA SEQ), so no stale value is reported."""
        request = default_on_pre_notify(request)
        notify = self._notify
        sid, seq = request.headers.get("SID"), request.headers.get("SEQ")
        if notify is None or sid is None or notify.event_handler.service_for_sid(sid) is None:
            return request  # not yet subscribed: the library keeps it and replays it after SUBSCRIBE
        try:
            number = int(seq or "")
        except ValueError:
            return request
        if number <= self._last_seq.get(sid, -1):
            return HttpRequest(request.method, request.url, request.headers, _EMPTY_PROPERTYSET)
        self._last_seq[sid] = number
        return request

    def _on_event(self, _service: UpnpService, variables: Sequence[UpnpStateVariable[Any]]) -> None:
        changes = [VariableChange(v.name, v.value) for v in variables if self._values.get(v.name, _UNSET) != v.value]
        self._values.update((v.name, v.value) for v in variables)
        if not self._baseline:  # the initial event (none before it can be stale)
            self._baseline = True
            self._changed.notify()
            return
        loop = asyncio.get_running_loop()
        for change in changes:
            if self._on_change is not None:
                loop.call_soon(self._on_change, change.variable, change.value)
            else:
                self.events.put_nowait(change)
        if changes:
            self._changed.notify()

    async def next_change(self, timeout: float | None = None) -> VariableChange:
        """The next change from :attr:`events`; :class:`~plugnproduce.errors.ProtocolTimeout` if none comes."""
        limit = self.timeout if timeout is None else timeout
        try:
            async with asyncio.timeout(limit):
                return await self.events.get()
        except TimeoutError as exc:
            raise ProtocolTimeout(f"{self._what()}: no event within {limit:g} s") from exc

    async def wait_until(self, predicate: Callable[[Mapping[str, Any]], bool], timeout: float | None = None) -> None:
        """Wait until ``predicate(values)`` holds for the received variable values."""
        await self._changed.wait_for(
            lambda: True if predicate(self._values) else None,
            self.timeout if timeout is None else timeout,
            f"waiting on {self._what()}",
        )

    async def _renew(self, seconds: int) -> None:
        notify = self._notify
        while notify is not None:
            await asyncio.sleep(seconds / 2)
            try:
                with upnp_errors(f"renewing the subscription to {self._what()}"):
                    await notify.event_handler.async_resubscribe(self._service, timeout=timedelta(seconds=seconds))
            except ProtocolError as exc:
                _LOGGER.warning("%s", exc)

    async def unsubscribe(self) -> None:
        """End the subscription and stop listening for events."""
        notify = self._notify
        if notify is None:
            return
        try:
            if notify.event_handler.sid_for_service(self._service) is not None:
                with upnp_errors(f"unsubscribing from {self._what()}"):
                    async with asyncio.timeout(self.timeout):
                        await notify.event_handler.async_unsubscribe(self._service)
        finally:
            await self._stop_notify()

    async def _stop_notify(self) -> None:
        renewal, self._renewal = self._renewal, None
        if renewal is not None:
            renewal.cancel()
            await asyncio.gather(renewal, return_exceptions=True)
        notify, self._notify = self._notify, None
        self._service.on_event = None
        if notify is not None:
            await notify.async_stop_server()

    async def fetch_files(self) -> RemoteFiles:
        """Fetch the device's Turtle description and SCXML chart from the URLs its description names."""
        urls = []
        for tag in ("descriptionURL", "chartURL"):
            reference = self._device.xml.findtext(f"{{{PNP_XML_NS}}}{tag}")
            if not reference:
                raise RemoteError(f"{self._what()}: its description has no pnp:{tag} element")
            urls.append(resolve_trusted(self.location, reference, self.trusted_host, f"pnp:{tag} of {self._what()}"))
        texts = [await self._fetch_text(url) for url in urls]
        return RemoteFiles(urls[0], texts[0], urls[1], texts[1])

    async def _fetch_text(self, url: str) -> str:
        what = f"fetching {url} from {self._what()}"
        with upnp_errors(what):
            async with asyncio.timeout(self.timeout):
                response = await self._requester.async_http_request(HttpRequest("GET", url, {}, None))
        if response.status_code != 200:
            raise RemoteError(f"{what}: the device answered HTTP {response.status_code}; expected 200")
        return response.body or ""

    async def close(self) -> None:
        """Unsubscribe if subscribed; a device already gone is not an error here."""
        try:
            await self.unsubscribe()
        except ProtocolError as exc:
            _LOGGER.debug("closing: %s", exc)


_UNSET = object()


def _checked_value(variable: UpnpStateVariable[Any], name: str, value: Any, what: str) -> Any:
    """``value`` in the argument's Python type, or a :class:`ProtocolError` saying what is allowed."""
    python_type = variable.data_type_mapping["type"]
    try:
        if isinstance(value, str) and python_type is not str:
            value = variable.coerce_python(value)
        elif python_type is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        variable.validate_value(value)
    except (UpnpValueError, ValueError) as exc:
        if variable.allowed_values:
            expected = "one of " + ", ".join(sorted(str(v) for v in variable.allowed_values))
        else:
            expected = f"a {variable.data_type}"
            if variable.min_value is not None or variable.max_value is not None:
                expected += f" in [{variable.min_value}, {variable.max_value}]"
        raise ProtocolError(f"{what}: argument {name!r} = {value!r} is refused; expected {expected}") from exc
    return value
