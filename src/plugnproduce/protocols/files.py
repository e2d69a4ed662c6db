"""A device's own description files, as both protocols serve them (one class for XIRP and UPnP)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from plugnproduce.errors import DescriptionError

FILE_NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]{0,127}")
"""A file name a device may serve its description under: plain, no folders, at most 128 characters."""


@dataclass(frozen=True)
class DeviceFiles:
    """A device's own description: Turtle metadata and SCXML chart, with their file names.

    ``description_name`` and ``chart_name`` are plain file names (``gripper.ttl``,
    ``gripper.scxml``): XIRP returns them in a ``describe`` response, UPnP serves them
    under ``/pnp/``; either way a relative ``pnp:stateChart <gripper.scxml>`` in the
    Turtle still resolves.
    """

    description_name: str
    description: str
    chart_name: str
    chart: str

    def __post_init__(self) -> None:
        for name in (self.description_name, self.chart_name):
            if not FILE_NAME_PATTERN.fullmatch(name):
                raise DescriptionError(f"file name {name!r} cannot be served; expected a plain file name")
        if self.description_name == self.chart_name:
            raise DescriptionError(f"description and chart share the file name {self.chart_name!r}")
