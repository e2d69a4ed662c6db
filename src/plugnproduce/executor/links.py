"""The controller's connections to the devices of a cell, one per device, over its protocol.

A link sends a device command (a request with parameters) and reports what comes back
through three callbacks: ``on_event(device, name, params)`` for a device event,
``on_lost(device, reason)`` when the connection ends, ``on_anomaly(device, what)``
for a message that should not have come (malformed, duplicated, an unsolicited error).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Mapping
from typing import Any, Protocol
from urllib.parse import urlparse

from plugnproduce.description.model import DeviceDescription
from plugnproduce.description.quantities.reports import reported_values
from plugnproduce.errors import ProtocolError
from plugnproduce.protocols import upnp, xirp

EventCallback = Callable[[str, str, Mapping[str, Any]], None]
ProblemCallback = Callable[[str, str], None]

CONNECT_TIMEOUT = 10.0
"""Seconds a device has at least to accept a connection and greet (a device's command timeout may be shorter:
a gripper answers a command in 2 s, but a busy host can take longer than that to accept a connection)."""


def connect_timeout(device: DeviceDescription) -> float:
    """How long opening a connection to ``device`` may take: its command timeout, at least :data:`CONNECT_TIMEOUT`."""
    return max(device.command_timeout, CONNECT_TIMEOUT)


class DeviceLink(Protocol):
    """A connection to one device."""

    device: str

    async def request(self, name: str, params: Mapping[str, Any], timeout: float) -> None:
        """Send a request and wait for the device to accept it (ProtocolError if it does not)."""
        ...

    async def state(self, timeout: float) -> str:
        """The device's current state as it reports it: the id of its device state chart's state."""
        ...

    async def close(self) -> None:
        """End the connection politely."""
        ...


class XirpLink:
    """A device driven over XIRP."""

    def __init__(self, device: str, client: xirp.XirpClient, on_lost: ProblemCallback) -> None:
        self.device = device
        self._client = client
        self._watch = asyncio.create_task(self._watch_connection(on_lost))

    @classmethod
    async def open(cls, device: DeviceDescription, on_event: EventCallback, on_lost: ProblemCallback,
                   on_anomaly: ProblemCallback) -> XirpLink:
        """Connect to the device's endpoint."""
        client = await xirp.XirpClient.connect_endpoint(
            device.endpoint, timeout=connect_timeout(device),
            on_event=lambda e: on_event(device.id, e.name, dict(e.params)))
        client.stats.on_anomaly = lambda what: on_anomaly(device.id, what)
        return cls(device.id, client, on_lost)

    async def _watch_connection(self, on_lost: ProblemCallback) -> None:
        await self._client.wait_closed()
        if self._client.lost is not None:
            on_lost(self.device, str(self._client.lost))

    async def request(self, name: str, params: Mapping[str, Any], timeout: float) -> None:
        await self._client.request(name, dict(params), timeout=timeout)

    async def state(self, timeout: float) -> str:
        return await self._client.state(timeout=timeout)

    async def close(self) -> None:
        self._watch.cancel()
        await self._client.close()


def _upnp_host(device: DeviceDescription) -> str:
    """The host a UPnP device's endpoint names: the only host its description and services are trusted on."""
    host = urlparse(device.endpoint).hostname
    if not host:
        raise ProtocolError(f"device {device.id}: endpoint {device.endpoint!r} names no host; "
                            "expected http://HOST:PORT/PATH")
    return host


class UpnpLink:
    """A device driven over UPnP: requests are SOAP actions, events are changes of evented counters.

    The values an event carries are its ``EVENT__NAME`` variables (JSON), changed in the same notification.
    """

    def __init__(self, device: str, client: upnp.UpnpDeviceClient) -> None:
        self.device = device
        self._client = client

    @classmethod
    async def open(cls, device: DeviceDescription, on_event: EventCallback, on_lost: ProblemCallback,
                   on_anomaly: ProblemCallback) -> UpnpLink:
        """Read the device's UPnP description (where it was discovered) and subscribe to its events."""
        client = await upnp.UpnpDeviceClient.connect(device.endpoint, _upnp_host(device),
                                                     timeout=connect_timeout(device))
        def changed(variable: str, _value: Any) -> None:
            if not upnp.is_payload_variable(variable):  # a value an event carries comes with its counter
                on_event(device.id, variable, upnp.payload_of(client.values, variable))

        await client.subscribe(changed)
        return cls(device.id, client)

    async def request(self, name: str, params: Mapping[str, Any], timeout: float) -> None:
        await self._client.invoke(name, {k: upnp.lexical(v) for k, v in params.items()}, timeout=timeout)

    async def state(self, timeout: float) -> str:
        results = await self._client.invoke(upnp.STATE_ACTION, {}, timeout=timeout)
        value = results.get(upnp.STATE_ARGUMENT)
        if not isinstance(value, str) or not value:
            raise ProtocolError(f"device {self.device}: {upnp.STATE_ACTION} answered no {upnp.STATE_ARGUMENT}")
        return value

    async def close(self) -> None:
        await self._client.close()


class OpcUaLink:
    """A device driven over OPC UA: requests are method calls, events are OPC UA events of the device object.

    A method's output arguments are the values of the event the device answers the request with at once
    (:meth:`DeviceDescription.answer_to`): they reach the chart as that event, as any produced value does.
    """

    def __init__(self, device: DeviceDescription, client: Any, on_event: EventCallback) -> None:
        self.device = device.id
        self._description = device
        self._client = client
        self._on_event = on_event

    @classmethod
    async def open(cls, device: DeviceDescription, on_event: EventCallback, on_lost: ProblemCallback,
                   on_anomaly: ProblemCallback) -> OpcUaLink:
        """Open a session with the device's server and subscribe to the events its chart sends."""
        from plugnproduce.protocols.opcua import OpcUaDeviceClient  # asyncua loads only for an OPC UA cell

        client = await OpcUaDeviceClient.connect(device.endpoint, device.id, connect_timeout(device))
        events = sorted({c.name for t in (*device.transitions, *device.stops) for c in t.sends if c.kind == "event"})
        try:
            await client.subscribe(events, lambda name, values: on_event(device.id, name, values),
                                   lambda reason: on_lost(device.id, reason),
                                   lambda what: on_anomaly(device.id, what), device.command_timeout)
        except BaseException:
            await client.close()
            raise
        return cls(device, client, on_event)

    async def request(self, name: str, params: Mapping[str, Any], timeout: float) -> None:
        outputs = await self._client.call(name, params, timeout)
        answer = self._description.answer_to(name)
        if answer is not None:
            self._on_event(self.device, answer, outputs)

    async def state(self, timeout: float) -> str:
        state: str = await self._client.state(timeout)
        return state

    async def close(self) -> None:
        await self._client.close()


async def query_report(device: DeviceDescription, timeout: float) -> tuple[str, dict[str, Any]]:
    """Connect to a device, ask its state and the values it reports with it (teach-in), disconnect.

    Each protocol's state query carries them: XIRP's ``state`` response as its other results, UPnP's
    ``GetDeviceState`` as its other out-arguments (JSON), OPC UA as the variables ``ns:QUANTITY`` beside
    ``ns:State``, read in one request. A value the device does not report is left out."""
    kinds = {"xirp": _xirp_report, "upnp": _upnp_report, "opcua": _opcua_report}
    if device.protocol not in kinds:
        raise ProtocolError(f"device {device.id}: protocol {device.protocol!r} is not supported; "
                            "expected xirp, upnp or opcua")
    return await kinds[device.protocol](device, sorted(reported_values(device)), timeout)


async def _xirp_report(device: DeviceDescription, _names: list[str], timeout: float) -> tuple[str, dict[str, Any]]:
    client = await xirp.XirpClient.connect_endpoint(device.endpoint, timeout=connect_timeout(device))
    try:
        return await client.report(timeout=timeout)
    finally:
        await client.close()


async def _upnp_report(device: DeviceDescription, names: list[str], timeout: float) -> tuple[str, dict[str, Any]]:
    client = await upnp.UpnpDeviceClient.connect(device.endpoint, _upnp_host(device), timeout=connect_timeout(device))
    try:
        results = await client.invoke(upnp.STATE_ACTION, {}, timeout=timeout)
    finally:
        await client.close()
    state = results.get(upnp.STATE_ARGUMENT)
    if not isinstance(state, str) or not state:
        raise ProtocolError(f"device {device.id}: {upnp.STATE_ACTION} answered no {upnp.STATE_ARGUMENT}")
    try:
        return state, upnp.reported_of(results, names, f"device {device.id}: {upnp.STATE_ACTION}")
    except ValueError as exc:
        raise ProtocolError(str(exc)) from None


async def _opcua_report(device: DeviceDescription, names: list[str], timeout: float) -> tuple[str, dict[str, Any]]:
    from plugnproduce.protocols.opcua import OpcUaDeviceClient  # asyncua loads only for an OPC UA device

    client = await OpcUaDeviceClient.connect(device.endpoint, device.id, connect_timeout(device))
    try:
        return await client.report(names, timeout)
    finally:
        await client.close()


async def query_state(device: DeviceDescription, timeout: float) -> str:
    """Connect to a device, ask its current state (the id of its device state chart's state), disconnect."""
    link = await open_link(device, lambda *_: None, lambda *_: None, lambda *_: None)
    try:
        return await link.state(timeout)
    finally:
        await link.close()


async def open_link(device: DeviceDescription, on_event: EventCallback, on_lost: ProblemCallback,
                    on_anomaly: ProblemCallback) -> DeviceLink:
    """Connect to a device over its protocol."""
    kinds: dict[str, Any] = {"xirp": XirpLink, "upnp": UpnpLink, "opcua": OpcUaLink}
    if device.protocol not in kinds:
        raise ProtocolError(f"device {device.id}: protocol {device.protocol!r} is not supported; "
                            "expected xirp, upnp or opcua")
    link: DeviceLink = await kinds[device.protocol].open(device, on_event, on_lost, on_anomaly)
    return link
