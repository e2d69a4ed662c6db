"""Teach-in: a value a device reports (a pose it was guided to), held to the device's contracts like any other.

The controller reads the value from the device (:func:`plugnproduce.controller.teaching`); this module says which
values a device reports (its chart's ``<data pnp:quantity=...>``,
:mod:`plugnproduce.description.quantities.reports`) and
judges one against every contract of the device's requests that take that quantity
(:func:`plugnproduce.description.quantities.contracts.breach`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from plugnproduce.description.model import Argument, DeviceDescription
from plugnproduce.description.quantities.contracts import breach, shorten
from plugnproduce.description.quantities.reports import ReportedValue, reported_values
from plugnproduce.errors import PlugNProduceError, UnknownName
from plugnproduce.ontology.iris import local_name


class ReportsNothing(PlugNProduceError):
    """A device whose chart declares no value it reports with its state."""


@dataclass(frozen=True)
class Taught:
    """A value read from a device, and what its contracts say of it."""

    device: str
    quantity: str
    value: Any
    state: str
    """The state the device reported with it."""
    unit: str
    held_to: tuple[str, ...]
    """The contracts it was held to, in words (``MoveTo TargetPose: reach 1.45 m``)."""
    refused: tuple[str, ...]
    """Why a contract refuses it (none: every one takes it)."""

    @property
    def accepted(self) -> bool:
        """Whether every contract takes the value."""
        return not self.refused

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {"device": self.device, "quantity": self.quantity, "value": self.value, "unit": self.unit,
                "state": self.state, "accepted": self.accepted, "held_to": list(self.held_to),
                "refused": list(self.refused)}

    def line(self) -> str:
        """``robot TargetPose = [0.4, 0.0, 0.6, 0, 180, 0] (robot is home)``."""
        unit = f" {self.unit}" if self.unit else ""
        return f"{self.device} {self.quantity} = {shorten(self.value, 200)}{unit} ({self.device} is {self.state})"


def reported_quantities(device: DeviceDescription) -> list[str]:
    """The quantities the device reports with its state (``TargetPose``), sorted."""
    return sorted(reported_values(device))


def reported_value(device: DeviceDescription, quantity: str) -> ReportedValue:
    """The value ``quantity`` the device reports (UnknownName, with those it does report; ReportsNothing)."""
    reports = reported_values(device)
    if not reports:
        raise ReportsNothing(f"device {device.id} reports no value with its state: its chart "
                             f"{device.chart_file.rsplit('/', 1)[-1]} has no <data pnp:quantity=...>")
    if quantity not in reports:
        raise UnknownName("reported quantity", quantity, reports, owner=f"device {device.id}")
    return reports[quantity]


def judge_taught(device: DeviceDescription, quantity: str, value: Any, state: str) -> Taught:
    """Hold a value the device reported to each contract of its requests that take ``quantity``."""
    reported = reported_value(device, quantity)
    contracts = [a for a in device.arguments if local_name(a.quantity) == quantity]
    value = _as_declared(value, contracts)
    held, refused = [], []
    for contract in contracts:
        held.append(f"{contract.request} {quantity}: {_limits(contract)}")
        why = breach(value, reported.unit, contract)
        if why is not None:
            refused.append(f"{device.id} {contract.request} {quantity} {why}")
    return Taught(device.id, quantity, value, state, reported.unit, tuple(held), tuple(refused))


def _as_declared(value: Any, contracts: list[Argument]) -> Any:
    """A pose whatever protocol carried it: six numbers as floats (JSON over UPnP keeps ``0`` an integer, XIRP and
    OPC UA Double[6] do not), when a contract takes the quantity as a Pose; any other value as it came."""
    if not any(local_name(c.datatype) == "Pose" for c in contracts if c.datatype):
        return value
    if isinstance(value, list) and len(value) == 6 and all(isinstance(v, int | float) and not isinstance(v, bool)
                                                            for v in value):
        return [float(v) for v in value]
    return value


def _limits(contract: Argument) -> str:
    parts = [local_name(contract.datatype)] if contract.datatype else []
    if contract.reach is not None:
        parts.append(f"reach {contract.reach:g} m")
    unit = f" {contract.unit}" if contract.unit else ""
    if contract.minimum is not None:
        parts.append(f"at least {contract.minimum:g}{unit}")
    if contract.maximum is not None:
        parts.append(f"at most {contract.maximum:g}{unit}")
    return ", ".join(parts) or "any value"
