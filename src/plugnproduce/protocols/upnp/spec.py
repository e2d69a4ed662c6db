"""What a Plug'n'Produce device publishes over UPnP, as plain data.

A device has one service, :data:`SERVICE_TYPE`. Its actions are the requests the
device's state chart waits for (``upnp.request.NAME``), its evented state variables
the events the chart sends (``upnp.event.NAME``). Nothing here touches a socket:
the device server and the simulator share these dataclasses, and
:func:`service_spec_from_chart_events` is the one place the chart-to-service rule
is written down.
"""

from __future__ import annotations

import json
import re
import uuid
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from async_upnp_client.const import STATE_VARIABLE_TYPE_MAPPING

from plugnproduce.errors import DescriptionError

PNP_DOMAIN = "plugnproduce-org"
"""The UPnP domain name of the project (``plugnproduce.org``, periods as hyphens)."""

SERVICE_TYPE = f"urn:{PNP_DOMAIN}:service:DeviceControl:1"
"""The one service every Plug'n'Produce device publishes."""

SERVICE_ID = f"urn:{PNP_DOMAIN}:serviceId:DeviceControl"
"""The service's id within the device."""

PNP_XML_NS = f"urn:{PNP_DOMAIN}:device-1-0"
"""Namespace of the vendor elements in the device description that point at the device's files."""

REQUEST_PREFIX = "upnp.request."
"""SCXML event prefix of a request the device waits for: ``upnp.request.MoveTo`` is action ``MoveTo``."""

EVENT_PREFIX = "upnp.event."
"""SCXML event prefix of an event the device sends: ``upnp.event.arrived`` is variable ``arrived``."""

RESULT_ARGUMENT = "Result"
"""Name of the one out-argument a chart-derived action returns."""

STATE_ACTION = "GetDeviceState"
"""The action that answers the device's current state (its device state chart's state id) in ``State``."""

STATE_ARGUMENT = "State"
"""The out-argument of :data:`STATE_ACTION`."""

ARG_TYPE_PREFIX = "A_ARG_TYPE_"
"""Prefix of the (non-evented) state variables that type action arguments (UPnP convention)."""

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_DEVICES_IRI = "http://plugnproduce.org/devices/"


def device_type_for(class_name: str) -> str:
    """The UPnP device type of a device class: ``Robot`` → ``urn:plugnproduce-org:device:Robot:1``."""
    _check_name(class_name, "device class name")
    return f"urn:{PNP_DOMAIN}:device:{class_name}:1"


def udn_for(device_id: str) -> str:
    """A stable UDN for a device id: a name-based UUID of the device's IRI, so it survives restarts."""
    return f"uuid:{uuid.uuid5(uuid.NAMESPACE_URL, _DEVICES_IRI + device_id)}"


def _check_name(name: str, what: str) -> None:
    if not _NAME.match(name):
        raise DescriptionError(
            f"{what} {name!r} cannot be a UPnP name; expected letters, digits and '_', not starting with a digit"
        )


def _check_type(data_type: str, what: str) -> None:
    if data_type not in STATE_VARIABLE_TYPE_MAPPING:
        known = ", ".join(sorted(STATE_VARIABLE_TYPE_MAPPING))
        raise DescriptionError(f"{what} has data type {data_type!r}; expected one of the UPnP types {known}")


def _check_allowed(data_type: str, allowed: Sequence[str], default: str | None, what: str) -> None:
    coerce = STATE_VARIABLE_TYPE_MAPPING[data_type]["in"]
    for value in allowed:
        try:
            coerce(value)
        except ValueError as exc:
            raise DescriptionError(f"{what}: allowed value {value!r} is not a {data_type}") from exc
    if len(set(allowed)) != len(allowed):
        raise DescriptionError(f"{what}: allowed values {list(allowed)} repeat a value")
    if default is not None and allowed and default not in allowed:
        raise DescriptionError(f"{what}: default {default!r} is not one of the allowed values {', '.join(allowed)}")


@dataclass(frozen=True)
class ArgumentSpec:
    """One argument of an action: its name, UPnP data type and, optionally, the values allowed."""

    name: str
    data_type: str = "string"
    allowed_values: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        _check_name(self.name, "argument name")
        _check_type(self.data_type, f"argument {self.name!r}")
        _check_allowed(self.data_type, self.allowed_values, None, f"argument {self.name!r}")


@dataclass(frozen=True)
class ActionSpec:
    """One action: its in-arguments and out-arguments (by default one string ``Result``)."""

    name: str
    inputs: tuple[ArgumentSpec, ...] = ()
    outputs: tuple[ArgumentSpec, ...] = (ArgumentSpec(RESULT_ARGUMENT),)

    def __post_init__(self) -> None:
        _check_name(self.name, "action name")
        names = [a.name for a in self.inputs] + [a.name for a in self.outputs]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise DescriptionError(f"action {self.name!r} names argument(s) {', '.join(repeated)} more than once")

    @property
    def input_names(self) -> tuple[str, ...]:
        """The names of the in-arguments, in order."""
        return tuple(a.name for a in self.inputs)


@dataclass(frozen=True)
class VariableSpec:
    """One evented state variable: a change of its value is sent to every subscriber (GENA)."""

    name: str
    data_type: str = "string"
    allowed_values: tuple[str, ...] = ()
    default: str | None = None

    def __post_init__(self) -> None:
        _check_name(self.name, "state variable name")
        if self.name.startswith(ARG_TYPE_PREFIX):
            raise DescriptionError(f"state variable {self.name!r}: the prefix {ARG_TYPE_PREFIX} is reserved")
        _check_type(self.data_type, f"state variable {self.name!r}")
        _check_allowed(self.data_type, self.allowed_values, self.default, f"state variable {self.name!r}")


@dataclass(frozen=True)
class ServiceSpec:
    """The device's one service: its actions and its evented state variables."""

    actions: tuple[ActionSpec, ...] = ()
    variables: tuple[VariableSpec, ...] = ()

    def __post_init__(self) -> None:
        for what, names in (("action", [a.name for a in self.actions]), ("variable", [v.name for v in self.variables])):
            repeated = sorted({n for n in names if names.count(n) > 1})
            if repeated:
                raise DescriptionError(f"{what} name(s) {', '.join(repeated)} given more than once")

    def action(self, name: str) -> ActionSpec:
        """The action called ``name``; :class:`KeyError` if there is none."""
        for action in self.actions:
            if action.name == name:
                return action
        raise KeyError(name)

    def variable(self, name: str) -> VariableSpec:
        """The state variable called ``name``; :class:`KeyError` if there is none."""
        for variable in self.variables:
            if variable.name == name:
                return variable
        raise KeyError(name)


PAYLOAD_SEPARATOR = "__"
"""Between an event's name and a value it carries, in the name of the variable holding that value."""


def payload_variable(event: str, name: str) -> str:
    """The evented string variable holding value ``name`` of event ``event`` (``PartLocalized__part_pose``)."""
    return f"{event}{PAYLOAD_SEPARATOR}{name}"


def is_payload_variable(variable: str) -> bool:
    """Whether a variable holds a value an event carries (not an event counter)."""
    return PAYLOAD_SEPARATOR in variable


def payload_of(values: Mapping[str, Any], event: str) -> dict[str, Any]:
    """The values event ``event`` carried, from the device's variables (JSON text; other text kept as it is)."""
    prefix = event + PAYLOAD_SEPARATOR
    out: dict[str, Any] = {}
    for variable, text in values.items():
        if variable.startswith(prefix):
            try:
                out[variable[len(prefix):]] = json.loads(text) if isinstance(text, str) else text
            except (ValueError, RecursionError):  # no JSON, or nested deeper than the decoder recurses
                out[variable[len(prefix):]] = text
    return out


def service_spec_from_chart_events(
    requests: Mapping[str, Sequence[str]],
    events: Sequence[str],
    argument_types: Mapping[str, str] | None = None,
    payloads: Mapping[str, Sequence[str]] | None = None,
) -> ServiceSpec:
    """Build the UPnP service of a device from the protocol events of its state chart.

    ``requests`` maps each request name (``MoveTo`` from a transition on
    ``upnp.request.MoveTo``) to the parameters the transition accepts (its
    ``pnp:accepts`` quantity names, e.g. ``["Pose"]``); each becomes an action with
    those in-arguments and one string out-argument ``Result``. A request that
    several transitions wait for appears once, with the union of their parameters.

    ``events`` lists the event names the chart sends (``arrived`` from
    ``<send event="upnp.event.arrived">``); each becomes an evented ``ui4`` state
    variable counting how often the event was sent (starting at 0), so every
    occurrence is a change a subscriber is told about, even the same event twice.

    Arguments are strings (their lexical form, e.g. a pose ``"0.4 0.1 0.2 0 180 0"``)
    unless ``argument_types`` gives a UPnP type for a parameter name.

    ``payloads`` names the values each event carries (its ``<param>`` names); each becomes an
    evented string variable ``EVENT__NAME`` holding the value as JSON, changed in the same
    notification as the event's counter.
    """
    types = dict(argument_types or {})
    actions = tuple(
        ActionSpec(name, tuple(ArgumentSpec(p, types.get(p, "string")) for p in _unique(params)))
        for name, params in sorted(requests.items())
    )
    variables = tuple(VariableSpec(name, "ui4", default="0") for name in sorted(set(events)))
    variables += tuple(VariableSpec(payload_variable(event, name), "string", default="null")
                       for event, names in sorted((payloads or {}).items()) for name in _unique(names))
    return ServiceSpec(actions, variables)


def with_state_query(spec: ServiceSpec, reports: Sequence[str] = ()) -> ServiceSpec:
    """The service with the state query :data:`STATE_ACTION` added (a chart request of that name is refused).

    ``reports`` are the quantities the device reports with its state (teach-in): each is one more string
    out-argument of the query, named after the quantity, holding the value as JSON (:func:`report_text`)."""
    if any(a.name == STATE_ACTION for a in spec.actions):
        raise DescriptionError(f"action {STATE_ACTION!r} is the state query; a device chart cannot wait for it")
    if STATE_ARGUMENT in reports:
        raise DescriptionError(f"a reported quantity cannot be named {STATE_ARGUMENT!r}: the state query's "
                               "out-argument of that name holds the state")
    outputs = (ArgumentSpec(STATE_ARGUMENT), *(ArgumentSpec(name) for name in _unique(reports)))
    return ServiceSpec((*spec.actions, ActionSpec(STATE_ACTION, outputs=outputs)), spec.variables)


MAX_REPORT = 4096
"""Longest text (characters) of a reported value the controller reads."""


def report_text(value: Any) -> str:
    """A value the device reports with its state, as the state query's out-argument carries it: JSON."""
    return json.dumps(value, allow_nan=False)


def reported_of(results: Mapping[str, Any], names: Sequence[str], where: str) -> dict[str, Any]:
    """The values of ``names`` in a state query's answer (those it carries), read from JSON within
    :data:`MAX_REPORT` characters; a :class:`ValueError` naming ``where`` and the value for anything else."""
    out: dict[str, Any] = {}
    for name in names:
        text = results.get(name)
        if text is None:
            continue
        if not isinstance(text, str) or len(text) > MAX_REPORT:
            raise ValueError(f"{where}: {name} is no text of at most {MAX_REPORT} characters")
        try:
            out[name] = json.loads(text, parse_constant=_no_constant)
        except (ValueError, RecursionError):  # nested deeper than the decoder recurses: no value either
            raise ValueError(f"{where}: {name} is not a JSON value: {text[:60]!r}") from None
    return out


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is no finite number")


def _unique(items: Sequence[str]) -> list[str]:
    seen: list[str] = []
    for item in items:
        if item not in seen:
            seen.append(item)
    return seen


@dataclass(frozen=True)
class RemoteFiles:
    """A device's description files as fetched from it, with the URLs they came from.

    Parse the Turtle with ``description_url`` as its base, so relative references
    (``pnp:stateChart <gripper.scxml>``) resolve to ``chart_url``.
    """

    description_url: str
    description: str
    chart_url: str
    chart: str
