"""async-upnp-client's server classes built for one device: its ``UpnpServerDevice`` and ``UpnpServerService``
subclasses from a :class:`~plugnproduce.protocols.upnp.spec.ServiceSpec`, and the control route that tells a
caller why an action was refused. :mod:`plugnproduce.protocols.upnp.device` serves them.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Awaitable, Callable, Mapping
from contextvars import ContextVar
from typing import Any, cast

from aiohttp import web
from async_upnp_client.const import STATE_VARIABLE_TYPE_MAPPING, DeviceInfo, ServiceInfo
from async_upnp_client.server import (
    SsdpSearchResponder,
    UpnpServerDevice,
    UpnpServerService,
    action_handler,
    callable_action,
    create_event_var,
    create_state_var,
)

from plugnproduce.protocols.upnp.spec import (
    ARG_TYPE_PREFIX,
    SERVICE_ID,
    SERVICE_TYPE,
    ActionSpec,
    ArgumentSpec,
    ServiceSpec,
)

ActionHandler = Callable[[str, Mapping[str, Any]], Awaitable[Mapping[str, Any]]]
"""``async handler(action_name, arguments) -> out-arguments``: what the device does when an action is invoked."""

DESCRIPTION_PATH = "/device.xml"
FILES_PATH = "/pnp/"
CONTROL_PATH = "/upnp/control/DeviceControl"
EVENT_PATH = "/upnp/event/DeviceControl"
SCPD_PATH = "/DeviceControl.xml"
CONTENT_TYPES = {".ttl": "text/turtle", ".scxml": "application/scxml+xml"}


DESCRIPTION_CHARS = 200
"""Most characters of a refusal's message sent as its UPnP error description."""

REFUSAL: ContextVar[str | None] = ContextVar("refusal", default=None)
"""The message of the refusal the action being answered ended with (set by the handler, read by the control route)."""


async def control_route(service: UpnpServerService, request: web.Request) -> web.StreamResponse:
    """The library's control route, with a refusal's own message as the error description.

    async-upnp-client always describes an action error as "Action Failed"; the caller would
    never learn why the device refused.
    """
    REFUSAL.set(None)
    response = await action_handler(service, request)
    message = REFUSAL.get()
    if message is None or not isinstance(response, web.Response) or response.body is None:
        return response
    root = ET.fromstring(cast(bytes, response.body))  # the library's own answer, not a peer's
    for element in root.iter("{urn:schemas-upnp-org:control-1-0}errorDescription"):
        element.text = message[:DESCRIPTION_CHARS]
    return web.Response(status=response.status, content_type="text/xml", charset="utf-8",
                        body=ET.tostring(root, encoding="utf-8", xml_declaration=True))


def _arg_var_name(action: ActionSpec, argument: ArgumentSpec) -> str:
    return f"{ARG_TYPE_PREFIX}{action.name}_{argument.name}"


def _action_method(action: ActionSpec, dispatch: ActionHandler) -> Callable[..., Any]:
    """A service method for ``action``, in the form ``callable_action`` expects (real-type annotations)."""

    async def invoke(self: UpnpServerService, **arguments: Any) -> Mapping[str, Any]:
        return await dispatch(action.name, arguments)

    invoke.__annotations__ = {a.name: STATE_VARIABLE_TYPE_MAPPING[a.data_type]["type"] for a in action.inputs}
    invoke.__name__ = f"action_{action.name}"
    method: Callable[..., Any] = callable_action(
        name=action.name,
        in_args={a.name: _arg_var_name(action, a) for a in action.inputs},
        out_args={a.name: _arg_var_name(action, a) for a in action.outputs},
    )(invoke)
    return method


def service_class(spec: ServiceSpec, dispatch: ActionHandler) -> type[UpnpServerService]:
    """Build the ``UpnpServerService`` subclass of one device's service."""
    variables: dict[str, Any] = {}
    for action in spec.actions:
        for argument in (*action.inputs, *action.outputs):
            allowed = list(argument.allowed_values) or None
            variables[_arg_var_name(action, argument)] = create_state_var(argument.data_type, allowed=allowed)
    for var in spec.variables:
        allowed = list(var.allowed_values) or None
        variables[var.name] = create_event_var(var.data_type, allowed=allowed, default=var.default)
    namespace: dict[str, Any] = {
        "SERVICE_DEFINITION": ServiceInfo(
            service_id=SERVICE_ID,
            service_type=SERVICE_TYPE,
            control_url=CONTROL_PATH,
            event_sub_url=EVENT_PATH,
            scpd_url=SCPD_PATH,
            xml=ET.Element("server_service"),
        ),
        "STATE_VARIABLE_DEFINITIONS": variables,
    }
    for action in spec.actions:
        namespace[f"action_{action.name}"] = _action_method(action, dispatch)
    return type("DeviceControlService", (UpnpServerService,), namespace)


def device_class(udn: str, device_type: str, friendly_name: str, service: type) -> type[UpnpServerDevice]:
    """Build the ``UpnpServerDevice`` subclass of one device."""
    info = DeviceInfo(
        device_type=device_type,
        friendly_name=friendly_name,
        manufacturer="Plug'n'Produce",
        manufacturer_url=None,
        model_description=None,
        model_name=friendly_name,
        model_number=None,
        model_url=None,
        serial_number=None,
        udn=udn,
        upc=None,
        presentation_url=None,
        url=DESCRIPTION_PATH,
        icons=[],
        xml=ET.Element("server_device"),
    )
    namespace = {"DEVICE_DEFINITION": info, "EMBEDDED_DEVICES": [], "SERVICES": [service]}
    return type("PnpDevice", (UpnpServerDevice,), namespace)


class SearchResponder(SsdpSearchResponder):
    """The library's search responder, also closing its reply socket on stop (0.49 leaves it open)."""

    async def async_stop(self) -> None:
        await super().async_stop()
        reply = getattr(self, "_response_transport", None)
        if reply is not None:
            reply.close()
