"""The controller side of OPC UA: an asyncua client for one device, after the naming rule of :mod:`.spec`.

Every read is bounded: each call by a timeout, each message by :data:`MAX_MESSAGE` bytes, arrays, strings and
argument lists by the limits of :mod:`.spec`; nodes are found by translating browse paths, never by walking
the address space. Whatever a server does wrong becomes a :class:`ProtocolError` naming the device.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from asyncua import Client, Node, ua
from asyncua.common.methods import call_method_full

from plugnproduce.errors import DescriptionError, ProtocolConnectionError, ProtocolError, ProtocolTimeout, RemoteError
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.opcua.identity import UserIdentity
from plugnproduce.protocols.opcua.security import PeerRefused, Security, check_plain, from_environment, secure_client
from plugnproduce.protocols.opcua.spec import (
    DESCRIPTION_OBJECT,
    DESCRIPTION_VARIABLES,
    MAX_ARGUMENTS,
    MAX_STRING,
    STATE_VARIABLE,
    Kind,
    from_wire,
    namespace_for,
    parse_endpoint,
    to_wire,
)
from plugnproduce.protocols.opcua.transport import bound_transport
from plugnproduce.safeio import MAX_BYTES

EventCallback = Callable[[str, dict[str, Any]], None]
"""Called with an event's name and its values."""
ProblemCallback = Callable[[str], None]

_KINDS: dict[int, Kind] = {ua.ObjectIds.Double: "double", ua.ObjectIds.Float: "double",
                           ua.ObjectIds.Int64: "int", ua.ObjectIds.Int32: "int", ua.ObjectIds.UInt32: "int",
                           ua.ObjectIds.Int16: "int", ua.ObjectIds.UInt16: "int",
                           ua.ObjectIds.Boolean: "bool", ua.ObjectIds.String: "string"}
_REFUSALS = {"BadInvalidState": "does not accept it in its current state",
             "BadInvalidArgument": "refused its arguments", "BadTypeMismatch": "refused its arguments' types"}

class OpcUaDeviceClient:
    """A session with one device's OPC UA server; make it with :meth:`connect`, end it with :meth:`close`."""

    def __init__(self, device: str, endpoint: str, client: Client, ns: int, node: Node) -> None:
        self.device = device
        self.endpoint = endpoint
        self._client = client
        self._ns = ns
        self._node = node
        self._methods: dict[str, tuple[Node, list[tuple[str, Kind]], list[str]]] = {}
        self._subscription: Any = None
        self.lost: str | None = None

    @classmethod
    async def connect(cls, endpoint: str, device: str, timeout: float,
                      security: Security | None = None) -> OpcUaDeviceClient:
        """Open a session and find the device's object by its browse path.

        ``security`` (default: from the environment, :func:`.security.from_environment`): mode None only on
        loopback, Sign or SignAndEncrypt with the PKI folder's certificates.
        """
        host = parse_endpoint(endpoint)[0]
        security = from_environment() if security is None else security
        check_plain(security, device, endpoint, host)
        client = Client(endpoint, timeout=timeout)
        bound_transport(client)
        identity: list[UserIdentity | None] = [None]
        try:
            await asyncio.wait_for(_secure_and_connect(client, security, device, identity), timeout)
        except TimeoutError as exc:
            await _quietly_close(client)
            raise ProtocolTimeout(f"device {device}: {endpoint} did not open a session within {timeout:g} s") \
                from exc
        except ProtocolError:
            await _quietly_close(client)
            raise
        except Exception as exc:  # any failure of a foreign server is a refused connection, never a crash
            await _quietly_close(client)
            raise ProtocolConnectionError(f"device {device}: cannot connect to {endpoint} "
                                          f"(security mode {security.mode}): "
                                          f"{_refusal(exc, security.mode, identity[0])}") from exc
        try:
            ns, node = await asyncio.wait_for(_device_node(client, device), timeout)
        except ProtocolError:
            await _quietly_close(client)
            raise
        except Exception as exc:
            await _quietly_close(client)
            raise _wrapped(exc, device, f"find its object at {endpoint}", timeout) from exc
        return cls(device, endpoint, client, ns, node)

    async def state(self, timeout: float) -> str:
        """The ``State`` variable: the id of the chart state the device is in."""
        return (await self.report((), timeout))[0]

    async def report(self, names: Sequence[str], timeout: float) -> tuple[str, dict[str, Any]]:
        """The ``State`` variable and, read with it in one request, the variable ``ns:NAME`` of each of ``names``
        the device has: the values it reports with its state (teach-in), by name."""
        try:
            state, values = await asyncio.wait_for(self._read_report(names[:MAX_ARGUMENTS]), timeout)
        except ProtocolError:
            raise
        except Exception as exc:
            raise _wrapped(exc, self.device, f"read its {STATE_VARIABLE}", timeout) from exc
        if not isinstance(state, str) or not state or len(state) > 256:
            raise ProtocolError(f"device {self.device}: {STATE_VARIABLE} is {str(state)[:80]!r}; "
                                "expected the id of a chart state")
        return state, {n: from_wire(v, f"device {self.device}: {n}") for n, v in values.items() if v is not None}

    async def _read_report(self, names: Sequence[str]) -> tuple[Any, dict[str, Any]]:
        nodes = {STATE_VARIABLE: await self._node.get_child(f"{self._ns}:{STATE_VARIABLE}")}
        for name in (n for n in names if n != STATE_VARIABLE):
            with contextlib.suppress(ua.UaStatusCodeError):  # BadNoMatch: the device does not report it
                nodes[name] = await self._node.get_child(f"{self._ns}:{name}")
        values = dict(zip(nodes, await self._client.read_values(list(nodes.values())), strict=True))
        return values.pop(STATE_VARIABLE), values

    async def call(self, name: str, params: Mapping[str, Any], timeout: float) -> dict[str, Any]:
        """Call the method ``name`` with ``params`` (by input argument name); its output arguments by name."""
        try:
            return await asyncio.wait_for(self._call(name, params), timeout)
        except ProtocolError:
            raise
        except Exception as exc:
            raise _wrapped(exc, self.device, f"call {name}", timeout) from exc

    async def _call(self, name: str, params: Mapping[str, Any]) -> dict[str, Any]:
        method, inputs, outputs = await self._method(name)
        unknown = sorted(set(params) - {n for n, _ in inputs})
        if unknown:
            raise ProtocolError(f"device {self.device}: method {name} takes no argument {unknown[0]}; "
                                f"it takes {', '.join(n for n, _ in inputs) or 'none'}")
        arguments = []
        for arg, kind in inputs:
            if arg not in params:
                raise ProtocolError(f"device {self.device}: method {name} needs argument {arg}; none given")
            value, vtype = to_wire(params[arg], kind, f"device {self.device}: {name} argument {arg}")
            arguments.append(ua.Variant(value, getattr(ua.VariantType, vtype)))
        values = list((await call_method_full(self._node, method, *arguments)).OutputArguments or [])
        if len(values) != len(outputs):
            raise ProtocolError(f"device {self.device}: method {name} answered {len(values)} output arguments; "
                                f"it declares {len(outputs)}")
        where = f"device {self.device}: {name} output"
        return {out: from_wire(v, f"{where} {out}") for out, v in zip(outputs, values, strict=True)}

    async def _method(self, name: str) -> tuple[Node, list[tuple[str, Kind]], list[str]]:
        if name not in self._methods:
            method = await self._node.get_child(f"{self._ns}:{name}")
            inputs = [(a.Name, _kind(a)) for a in await _arguments(method, "InputArguments", self.device, name)]
            outputs = [a.Name for a in await _arguments(method, "OutputArguments", self.device, name)]
            self._methods[name] = (method, inputs, outputs)
        return self._methods[name]

    async def subscribe(self, events: Sequence[str], on_event: EventCallback, on_lost: ProblemCallback,
                        on_anomaly: ProblemCallback, timeout: float) -> None:
        """Subscribe to the device object's events of the types ``ns:NAME`` for each of ``events``."""
        try:
            await asyncio.wait_for(self._subscribe(events, on_event, on_lost, on_anomaly), timeout)
        except ProtocolError:
            raise
        except Exception as exc:
            raise _wrapped(exc, self.device, "subscribe to its events", timeout) from exc

    async def _subscribe(self, events: Sequence[str], on_event: EventCallback, on_lost: ProblemCallback,
                         on_anomaly: ProblemCallback) -> None:
        types: dict[ua.NodeId, str] = {}
        base = self._client.get_node(ua.ObjectIds.BaseEventType)
        for name in events:
            node = await base.get_child(f"{self._ns}:{name}")
            types[node.nodeid] = name
        handler = _Events(self, types, on_event, on_lost, on_anomaly)
        _on_close(self._client, lambda: handler.lost("the server closed the connection"))
        self._subscription = await self._client.create_subscription(50, handler)
        if types:
            await self._subscription.subscribe_events(self._node, [self._client.get_node(t) for t in types])

    async def fetch_files(self, timeout: float) -> DeviceFiles:
        """The device's own description files, read from ``ns:Description`` (each at most ``MAX_BYTES``)."""
        try:
            texts = await asyncio.wait_for(self._read_files(), timeout)
        except ProtocolError:
            raise
        except Exception as exc:
            raise _wrapped(exc, self.device, f"read its {DESCRIPTION_OBJECT}", timeout) from exc
        try:
            return DeviceFiles(*texts)
        except DescriptionError as exc:
            raise ProtocolError(f"device {self.device}: {exc.message}") from exc

    async def _read_files(self) -> list[str]:
        folder = await self._node.get_child(f"{self._ns}:{DESCRIPTION_OBJECT}")
        texts = []
        for name in DESCRIPTION_VARIABLES:
            value = await (await folder.get_child(f"{self._ns}:{name}")).read_value()
            if not isinstance(value, str) or not value or len(value.encode("utf-8")) > MAX_BYTES:
                raise ProtocolError(f"device {self.device}: {DESCRIPTION_OBJECT}/{name} is no text of 1 to "
                                    f"{MAX_BYTES} bytes")
            texts.append(value)
        return texts

    async def close(self) -> None:
        """End the session (politely when the server still answers); its end is then no lost connection."""
        if self.lost is None:
            self.lost = "closed by the controller"
        await _quietly_close(self._client)


class _Events:
    """The subscription's handler: an event of a known type becomes ``on_event(name, values)``."""

    def __init__(self, client: OpcUaDeviceClient, types: dict[ua.NodeId, str], on_event: EventCallback,
                 on_lost: ProblemCallback, on_anomaly: ProblemCallback) -> None:
        self._client, self._types = client, types
        self._on_event, self._on_lost, self._on_anomaly = on_event, on_lost, on_anomaly
        self._fields: dict[str, set[str]] = {}

    def event_notification(self, event: Any) -> None:
        fields = event.get_event_props_as_fields_dict()
        name = self._types.get(getattr(event, "EventType", None))
        if name is None:
            self._on_anomaly(f"an event of an unknown type {str(getattr(event, 'EventType', None))[:80]}")
            return
        values: dict[str, Any] = {}
        try:
            for field, variant in list(fields.items())[:MAX_ARGUMENTS + 16]:
                if field not in _STANDARD_FIELDS and variant.Value is not None:
                    values[field] = from_wire(variant.Value, f"device {self._client.device}: event {name} {field}")
        except ProtocolError as exc:
            self._on_anomaly(str(exc))
            return
        self._on_event(name, values)

    def status_change_notification(self, status: Any) -> None:
        self.lost(f"the OPC UA session ended ({getattr(status, 'Status', status)})")

    def lost(self, reason: str) -> None:
        """Tell the first way the session was found lost (the socket closing, the watchdog's failed read)."""
        if self._client.lost is None:
            self._client.lost = reason
            self._on_lost(reason)

    def datachange_notification(self, *_: Any) -> None:
        """Not subscribed to: nothing to do."""


_STANDARD_FIELDS = frozenset({"EventId", "EventType", "SourceNode", "SourceName", "Time", "ReceiveTime",
                              "LocalTime", "Message", "Severity", "ConditionClassId", "ConditionClassName",
                              "ConditionSubClassId", "ConditionSubClassName"})
"""The fields every ``BaseEventType`` has; the others are the values an event carries."""


def _on_close(client: Client, then: Callable[[], None]) -> None:
    """Call ``then`` as soon as the connection's socket closes: asyncua's own watchdog notices a closed session
    only at its next read, a second or more later."""
    protocol = client.uaclient.protocol
    if protocol is None:
        return
    closed = protocol.connection_lost

    def connection_lost(exc: Exception | None) -> None:
        closed(exc)
        then()

    protocol.connection_lost = connection_lost


async def _secure_and_connect(client: Client, security: Security, device: str,
                              identity: list[UserIdentity | None]) -> None:
    """Connect with the security and user identity of ``device``, the identity given kept in ``identity``."""
    identity[0] = await secure_client(client, security, device)
    await client.connect()


_CERTIFICATE_REFUSALS = {
    "BadCertificateUntrusted": "its certificate is not among the trusted ones (PKI/trusted)",
    "BadCertificateUriInvalid": "its certificate does not name its application URI",
    "BadCertificateTimeInvalid": "its certificate has expired or is not valid yet",
}


_IDENTITY_REFUSALS = frozenset({"BadIdentityTokenRejected", "BadIdentityTokenInvalid", "BadUserAccessDenied"})


def _refusal(exc: BaseException, mode: str, identity: UserIdentity | None = None) -> str:
    """What a failed connection says, a refused certificate in words (refused by the controller, its own
    validator, or by the device), or a refused user identity."""
    if isinstance(exc, ua.UaStatusCodeError):
        name = type(exc).__name__
        if name in _IDENTITY_REFUSALS and identity is None:
            return f"{name}: the device asks for a user name and password; the users file gives none for it " \
                   "(PNP_OPCUA_USERS)"
        if name in _IDENTITY_REFUSALS and identity is not None:
            return f"{name}: the device refused the user {identity.user!r} of {identity.source}"
        if isinstance(exc.__cause__, PeerRefused):
            return f"{name}: {_CERTIFICATE_REFUSALS.get(name, 'its certificate is refused')}"
        if name.startswith("BadCertificate") or name == "BadSecurityChecksFailed":
            return f"{name}: the device refused the controller's certificate (PKI/own/cert.der is not among " \
                   "the certificates it trusts)"
    if str(exc).startswith("No matching endpoints"):
        return f"the device offers no endpoint with security mode {mode} ({_said(exc)})"
    return _said(exc)


async def _device_node(client: Client, device: str) -> tuple[int, Node]:
    namespaces = await client.get_namespace_array()
    if not isinstance(namespaces, list) or len(namespaces) > 4096:
        raise ProtocolError(f"device {device}: the server's namespace array is not a list of at most 4096 URIs")
    uri = namespace_for(device)
    if uri not in namespaces:
        raise ProtocolError(f"device {device}: the server has no namespace {uri}")
    ns = namespaces.index(uri)
    return ns, await client.nodes.objects.get_child(f"{ns}:{device}")


async def _arguments(method: Node, which: str, device: str, name: str) -> list[ua.Argument]:
    try:
        node = await method.get_child(f"0:{which}")
    except ua.UaStatusCodeError:
        return []  # a method without inputs (or outputs) may leave the property out
    value = await node.read_value()
    if value is None:
        return []
    if not isinstance(value, list) or len(value) > MAX_ARGUMENTS or \
            not all(isinstance(getattr(a, "Name", None), str) and 0 < len(a.Name) <= 128
                    and isinstance(getattr(a, "DataType", None), ua.NodeId) for a in value):
        raise ProtocolError(f"device {device}: method {name} has no readable {which} (at most {MAX_ARGUMENTS} "
                            "named arguments)")
    return value


def _kind(argument: ua.Argument) -> Kind:
    datatype = argument.DataType
    kind = _KINDS.get(datatype.Identifier, "any") if datatype.NamespaceIndex == 0 else "any"
    if argument.ValueRank == 1 and kind == "double":
        return "pose"
    return kind if argument.ValueRank in (-1, -3) else "any"


async def _quietly_close(client: Client) -> None:
    with contextlib.suppress(Exception):
        await asyncio.wait_for(client.disconnect(), 2.0)


def _said(exc: BaseException) -> str:
    text = str(exc) or type(exc).__name__
    return text[:200] + ("…" if len(text) > 200 else "")


def _wrapped(exc: BaseException, device: str, what: str, timeout: float) -> ProtocolError:
    """A failure of ``what`` as the ProtocolError the controller reports."""
    if isinstance(exc, TimeoutError):
        return ProtocolTimeout(f"device {device}: no answer to {what} within {timeout:g} s")
    if isinstance(exc, ua.UaStatusCodeError):
        code = type(exc).__name__ if type(exc) is not ua.UaStatusCodeError else _said(exc)
        why = _REFUSALS.get(code, "answered with an error")
        return RemoteError(f"device {device} {why}: {what}: {code}"[:MAX_STRING])
    if isinstance(exc, (ConnectionError, OSError)):
        return ProtocolConnectionError(f"device {device}: connection lost during {what}: {_said(exc)}")
    return ProtocolError(f"device {device}: {what} failed: {_said(exc)}")
