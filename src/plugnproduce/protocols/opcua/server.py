"""The device side of OPC UA: an asyncua server publishing one device after the naming rule of :mod:`.spec`.

The server listens on loopback (or the host it is given) with the one security mode it is given (None by
default), answers each method call
through a handler (the simulated device's chart), serves the chart state it is in as the ``State``
variable (read when asked, never stale) and sends the chart's events as OPC UA events of the device object.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Awaitable, Callable, Mapping
from typing import Any
from urllib.parse import urlparse

from asyncua import Node, Server, ua

from plugnproduce.errors import PlugNProduceError, ProtocolError
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.opcua.security import Security, secure_server
from plugnproduce.protocols.opcua.space import new_server
from plugnproduce.protocols.opcua.spec import (
    DESCRIPTION_OBJECT,
    DESCRIPTION_VARIABLES,
    REGISTRATION_PERIOD,
    STATE_VARIABLE,
    ArgumentSpec,
    Kind,
    MethodSpec,
    NodeSpec,
    application_uri_for,
    format_endpoint,
    from_wire,
)

REGISTER_TIMEOUT = 5.0
"""Seconds a registration with (or leaving of) a Local Discovery Server may take."""

RequestHandler = Callable[[str, Mapping[str, Any]], Awaitable[Mapping[str, Any] | None]]
"""Takes a request and its arguments; returns the values of its output arguments, or raises
:class:`RequestRefused`."""

_TYPES: dict[Kind, tuple[int, int, list[int]]] = {
    "double": (ua.ObjectIds.Double, -1, []), "int": (ua.ObjectIds.Int64, -1, []),
    "bool": (ua.ObjectIds.Boolean, -1, []), "string": (ua.ObjectIds.String, -1, []),
    "pose": (ua.ObjectIds.Double, 1, [6]), "any": (ua.ObjectIds.BaseDataType, -2, []),
}
"""Per kind: the argument's DataType, ValueRank (-1 scalar, 1 array, -2 any) and ArrayDimensions."""

for _name in ("asyncua.server", "asyncua.server.server", "asyncua.server.address_space",
              "asyncua.server.uaprocessor", "asyncua.server.binary_server_asyncio"):
    logging.getLogger(_name).setLevel(logging.ERROR)  # security-None and method-failure chatter


class RequestRefused(PlugNProduceError):  # noqa: N818 - what the device says
    """The device does not take the request now (``BadInvalidState``) or its arguments (``BadInvalidArgument``)."""

    def __init__(self, message: str, bad_arguments: bool = False) -> None:
        super().__init__(message)
        self.status = ua.StatusCodes.BadInvalidArgument if bad_arguments else ua.StatusCodes.BadInvalidState


class OpcUaDeviceServer:
    """One device as an OPC UA server; ``await start()``, ``await stop()``."""

    def __init__(self, spec: NodeSpec, handler: RequestHandler, state: Callable[[], str], *,
                 host: str = "127.0.0.1", port: int = 0,
                 files: Callable[[str], DeviceFiles] | None = None, security: Security | None = None,
                 reported: Callable[[str], Any] | None = None) -> None:
        """``files``: the device's own description for the endpoint it listens on, served as the String
        variables of ``ns:Description``; ``security``: the one mode it offers (default None) and its PKI
        folder; ``reported``: the value of a quantity it reports with its state, as it is when read."""
        self.security = security or Security()
        self.spec = spec
        self.files = files
        self._handler = handler
        self._state = state
        self._reported = reported or (lambda _quantity: None)
        self._host = host
        self._port = port
        self._server: Server | None = None
        self._events: dict[str, Any] = {}
        self._device: Node | None = None
        self.endpoint: str | None = None
        """``opc.tcp://HOST:PORT/pnp/DEVICE`` once started."""
        self._registered: list[str] = []

    async def start(self) -> None:
        """Build the address space and listen."""
        server = await new_server()  # the standard address space as kept, not built again
        server.set_server_name(f"Plug'n'Produce {self.spec.device}")
        server.set_endpoint(format_endpoint(self._host, self._port, f"/pnp/{self.spec.device}"))
        await secure_server(server, self.security, self.spec.device)
        await server.set_application_uri(application_uri_for(self.spec.device))
        idx = await server.register_namespace(self.spec.namespace)
        self._device = await server.nodes.objects.add_object(idx, self.spec.device)
        state = await self._device.add_variable(idx, STATE_VARIABLE, "", varianttype=ua.VariantType.String)
        server.iserver.set_attribute_value_callback(state.nodeid, self._read_state)
        for report in self.spec.reports:
            await self._add_report(server, idx, report)
        for method in self.spec.methods:
            await self._add_method(idx, method)
        for name, fields in self.spec.events.items():
            etype = await server.create_custom_event_type(
                idx, name, ua.ObjectIds.BaseEventType,
                [(f, ua.VariantType.Variant, ua.NodeId(ua.ObjectIds.BaseDataType)) for f in fields])
            self._events[name] = await server.get_event_generator(etype, self._device)
        await server.start()
        self._server = server
        port = server.bserver._server.sockets[0].getsockname()[1]
        self.endpoint = format_endpoint(self._host, port, f"/pnp/{self.spec.device}")
        if self.files is not None:
            await self._add_files(idx, self.files(self.endpoint))

    async def _add_files(self, idx: int, files: DeviceFiles) -> None:
        assert self._device is not None
        folder = await self._device.add_object(idx, DESCRIPTION_OBJECT)
        for name, value in zip(DESCRIPTION_VARIABLES, (files.description_name, files.description, files.chart_name,
                                                       files.chart), strict=True):
            await folder.add_variable(idx, name, value, varianttype=ua.VariantType.String)

    async def register(self, lds: str, period: int = REGISTRATION_PERIOD) -> None:
        """Register with the Local Discovery Server at ``lds`` (``RegisterServer``), under the real endpoint,
        renewed every ``period`` seconds (0: never) until stopped."""
        if self._server is None or self.endpoint is None:
            raise RuntimeError(f"device {self.spec.device}: start the server before registering it")
        self._server.endpoint = urlparse(self.endpoint)  # the port it listens on, not the 0 it was asked for
        try:
            await asyncio.wait_for(self._server.register_to_discovery(lds, period=period), REGISTER_TIMEOUT)
        except Exception as exc:  # an LDS that is not there or not an LDS: said, one line
            raise ProtocolError(f"device {self.spec.device}: cannot register with the Local Discovery Server "
                                f"{lds}: {str(exc)[:200] or type(exc).__name__}") from exc
        self._registered.append(lds)

    async def stop(self) -> None:
        """Leave the Local Discovery Servers it registered with (offline at once), then stop listening (the
        connected clients lose their sessions)."""
        if self._server is not None:
            server, self._server = self._server, None
            for lds in self._registered:
                with contextlib.suppress(Exception):  # a gone LDS forgets the registration by itself
                    await asyncio.wait_for(server.unregister_from_discovery(lds), REGISTER_TIMEOUT)
            self._registered.clear()
            await server.stop()

    def _read_state(self, *_: Any) -> ua.DataValue:
        return ua.DataValue(ua.Variant(self._state(), ua.VariantType.String))

    async def _add_report(self, server: Server, idx: int, report: ArgumentSpec) -> None:
        """A variable holding a value the device reports, read when asked (never stale), typed by its kind."""
        assert self._device is not None
        datatype, rank, dimensions = _TYPES[report.kind]
        node = await self._device.add_variable(idx, report.name, _variant(self._reported(report.name)),
                                               datatype=ua.NodeId(datatype))
        await node.write_value_rank(rank)
        await node.write_array_dimensions(dimensions)

        def read(*_: Any) -> ua.DataValue:
            return ua.DataValue(_variant(self._reported(report.name)))

        server.iserver.set_attribute_value_callback(node.nodeid, read)

    async def _add_method(self, idx: int, method: MethodSpec) -> None:
        assert self._device is not None
        inputs = [_argument(a.name, a.kind) for a in method.inputs]
        outputs = [_argument(name, "any") for name in method.outputs]

        async def call(_parent: ua.NodeId, *arguments: ua.Variant) -> Any:
            return await self._call(method, arguments)

        await self._device.add_method(idx, method.name, call, inputs, outputs)

    async def _call(self, method: MethodSpec, arguments: tuple[ua.Variant, ...]) -> Any:
        if len(arguments) != len(method.inputs):
            return ua.StatusCode(ua.StatusCodes.BadArgumentsMissing if len(arguments) < len(method.inputs)
                                 else ua.StatusCodes.BadTooManyArguments)
        try:
            values = {a.name: from_wire(v.Value, f"{method.name} {a.name}")
                      for a, v in zip(method.inputs, arguments, strict=True)}
            results = await self._handler(method.name, values) or {}
        except RequestRefused as exc:
            return ua.StatusCode(exc.status)
        except ProtocolError:
            return ua.StatusCode(ua.StatusCodes.BadInvalidArgument)
        return [_variant(results.get(name)) for name in method.outputs]

    async def emit(self, name: str, values: Mapping[str, Any]) -> None:
        """Send the event ``name`` with its fields set to ``values``."""
        generator = self._events.get(name)
        if generator is None or self._server is None:
            return
        for field_name in self.spec.events[name]:
            setattr(generator.event, field_name, _variant(values.get(field_name)))
        await generator.trigger(message=name)


def _argument(name: str, kind: Kind) -> ua.Argument:
    datatype, rank, dimensions = _TYPES[kind]
    return ua.Argument(Name=name, DataType=ua.NodeId(datatype), ValueRank=rank, ArrayDimensions=dimensions,
                       Description=ua.LocalizedText(name))


def _variant(value: Any) -> ua.Variant:
    """A value of the chart as a Variant: numbers in a list (a pose) as Double[], anything else as asyncua
    guesses (float: Double, int: Int64, str: String, bool: Boolean)."""
    if isinstance(value, (list, tuple)) and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                for v in value):
        return ua.Variant([float(v) for v in value], ua.VariantType.Double)
    if isinstance(value, (list, tuple)):
        return ua.Variant([str(v) for v in value], ua.VariantType.String)
    return ua.Variant(value)
