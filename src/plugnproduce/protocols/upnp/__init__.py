"""UPnP for Plug'n'Produce devices, on async-upnp-client.

* Device side: :class:`UpnpDeviceServer` publishes a device (description, one
  service with actions and evented variables, its own Turtle and SCXML files).
* Controller side: :func:`discover`, :class:`DeviceSearch`,
  :class:`AdvertisementListener`, :func:`describe` and :class:`UpnpDeviceClient`.
* :func:`service_spec_from_chart_events` turns a device chart's ``upnp.request.*``
  and ``upnp.event.*`` events into the service the device publishes.

See ``docs/upnp.md``.
"""

from __future__ import annotations

from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.upnp.advertisements import AdvertisementListener
from plugnproduce.protocols.upnp.boundary import (
    LOOPBACK,
    SsdpNetwork,
    UntrustedUrlError,
    network_from_env,
    private_network,
)
from plugnproduce.protocols.upnp.client import UpnpDeviceClient, VariableChange
from plugnproduce.protocols.upnp.device import (
    ARGUMENT_VALUE_INVALID,
    NOT_ACCEPTED_NOW,
    ActionFailed,
    UpnpDeviceServer,
)
from plugnproduce.protocols.upnp.discovery import (
    DeviceSearch,
    Discovery,
    FoundDevice,
    Refusal,
    SearchHit,
    describe,
    discover,
)
from plugnproduce.protocols.upnp.serverclasses import ActionHandler
from plugnproduce.protocols.upnp.spec import (
    EVENT_PREFIX,
    REQUEST_PREFIX,
    SERVICE_TYPE,
    STATE_ACTION,
    STATE_ARGUMENT,
    ActionSpec,
    ArgumentSpec,
    RemoteFiles,
    ServiceSpec,
    VariableSpec,
    device_type_for,
    is_payload_variable,
    payload_of,
    payload_variable,
    report_text,
    reported_of,
    service_spec_from_chart_events,
    udn_for,
    with_state_query,
)
from plugnproduce.protocols.upnp.ssdp import Advertisement
from plugnproduce.protocols.upnp.values import lexical, parse_lexical

__all__ = [
    "ARGUMENT_VALUE_INVALID",
    "EVENT_PREFIX",
    "LOOPBACK",
    "NOT_ACCEPTED_NOW",
    "REQUEST_PREFIX",
    "SERVICE_TYPE",
    "STATE_ACTION",
    "STATE_ARGUMENT",
    "ActionFailed",
    "ActionHandler",
    "ActionSpec",
    "Advertisement",
    "AdvertisementListener",
    "ArgumentSpec",
    "DeviceFiles",
    "DeviceSearch",
    "Discovery",
    "FoundDevice",
    "Refusal",
    "RemoteFiles",
    "SearchHit",
    "ServiceSpec",
    "SsdpNetwork",
    "UntrustedUrlError",
    "UpnpDeviceClient",
    "UpnpDeviceServer",
    "VariableChange",
    "VariableSpec",
    "describe",
    "device_type_for",
    "is_payload_variable",
    "lexical",
    "parse_lexical",
    "payload_of",
    "payload_variable",
    "report_text",
    "reported_of",
    "discover",
    "network_from_env",
    "private_network",
    "service_spec_from_chart_events",
    "udn_for",
    "with_state_query",
]
