"""OPC UA for Plug'n'Produce devices, on asyncua.

* :mod:`~plugnproduce.protocols.opcua.spec`: the naming rule (a device's namespace, object, methods, ``State``
  variable and event types), the value types and the limits on what the controller reads.
* Device side: :class:`OpcUaDeviceServer` publishes one device (its chart's requests as methods, its events
  as OPC UA events).
* Controller side: :class:`OpcUaDeviceClient`.

The client and server load asyncua when first named (``from plugnproduce.protocols.opcua import
OpcUaDeviceClient``); the naming rule and the endpoint syntax do not, so reading a cell stays quick.

See ``docs/opcua.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names
from plugnproduce.protocols.opcua.spec import (
    EVENT_PREFIX,
    MAX_ARRAY,
    MAX_STRING,
    NAMESPACE_PREFIX,
    REQUEST_PREFIX,
    STATE_VARIABLE,
    ArgumentSpec,
    Kind,
    MethodSpec,
    NodeSpec,
    format_endpoint,
    kind_of,
    namespace_for,
    parse_endpoint,
)

if TYPE_CHECKING:
    from plugnproduce.protocols.opcua.client import OpcUaDeviceClient
    from plugnproduce.protocols.opcua.server import OpcUaDeviceServer, RequestHandler, RequestRefused

_LAZY = {"OpcUaDeviceClient": ".client", "OpcUaDeviceServer": ".server", "RequestHandler": ".server",
         "RequestRefused": ".server"}
"""The client and server classes, imported (with asyncua) when first asked for."""

__getattr__, __dir__ = lazy_names(__name__, _LAZY)

__all__ = [
    "EVENT_PREFIX",
    "MAX_ARRAY",
    "MAX_STRING",
    "NAMESPACE_PREFIX",
    "REQUEST_PREFIX",
    "STATE_VARIABLE",
    "ArgumentSpec",
    "Kind",
    "MethodSpec",
    "NodeSpec",
    "OpcUaDeviceClient",
    "OpcUaDeviceServer",
    "RequestHandler",
    "RequestRefused",
    "format_endpoint",
    "kind_of",
    "namespace_for",
    "parse_endpoint",
]
