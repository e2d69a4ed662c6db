"""How long a device takes to carry out a request: the device's declared request durations.

A device description may declare, per request, either a fixed time or a motion model::

    dev:gripper pnp:hasDuration [ pnp:forRequest "Close" ; pnp:seconds 0.3 ] .
    dev:robot pnp:hasDuration [ pnp:forRequest "MoveTo" ; pnp:motionOf pnp:TargetPose ;
                                pnp:topSpeed 0.8 ; pnp:speedShare pnp:Speed ] .

A request with no declared duration takes what its Device State Chart says: the delays of the
``<send delay="...">`` elements it waits for. A motion model takes the straight-line distance between
the previous and the requested position (the first three items of the pose, in metres) over the speed:
``topSpeed`` (m/s) times the share the request's ``speedShare`` argument asks for (a percentage,
capped at the argument's declared maximum). A device's first move, from a pose no request named, takes
its chart's delay.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from plugnproduce.description.model import Where
from plugnproduce.ontology.iris import local_name


@dataclass(frozen=True)
class RequestDuration:
    """A device's declared duration of one request: ``seconds`` fixed, or a motion model."""

    request: str
    seconds: float | None = None
    motion_of: str | None = None
    """The quantity (IRI) of the request's pose argument whose distance the device travels."""
    top_speed: float | None = None
    """Metres per second at full speed."""
    speed_share: str | None = None
    """The quantity (IRI) of the request's argument that asks for a share of the top speed, in %."""
    where: Where | None = None

    @property
    def is_motion(self) -> bool:
        """Whether the duration follows the distance travelled."""
        return self.motion_of is not None


def distance(a: object, b: object) -> float | None:
    """Straight-line distance between the positions of two poses (None: either is not a pose)."""
    pa, pb = _position(a), _position(b)
    if pa is None or pb is None:
        return None
    return math.dist(pa, pb)


def _position(value: object) -> tuple[float, float, float] | None:
    """The position (x, y, z) of a pose: a list of numbers, or six numbers written in a string."""
    if isinstance(value, str):
        value = value.split()
    if not isinstance(value, (list, tuple)) or len(value) < 3:
        return None
    try:
        x, y, z = (float(v) for v in value[:3])
    except (TypeError, ValueError):
        return None
    return (x, y, z) if all(math.isfinite(v) for v in (x, y, z)) else None


class RequestTimer:
    """The declared durations of one device's requests, with the pose its last motion request named."""

    def __init__(self, durations: tuple[RequestDuration, ...], speed_limit: float = 100.0) -> None:
        """``speed_limit``: the largest share of its top speed (%) the device takes."""
        self._durations = {d.request: d for d in durations}
        self._speed_limit = speed_limit
        self._pose: object = None

    @property
    def pose(self) -> object:
        """The pose its last motion request named (None: unknown)."""
        return self._pose

    @pose.setter
    def pose(self, pose: object) -> None:
        self._pose = pose

    def seconds(self, request: str, values: Mapping[str, object]) -> float | None:
        """The time of ``request`` with argument ``values`` (keyed by the quantities' local names, as they go
        over the wire) as declared; None when
        the chart's delays count (no declaration, or a motion from or to an unknown pose). A motion request
        moves the remembered pose."""
        d = self._durations.get(request)
        if d is None:
            return None
        if not d.is_motion:
            return d.seconds
        target = values.get(local_name(d.motion_of or ""))
        travelled = distance(self._pose, target)
        self._pose = target if _position(target) is not None else None
        if travelled is None or not d.top_speed:
            return None
        share = _share(values.get(local_name(d.speed_share)), self._speed_limit) if d.speed_share else 100.0
        return travelled / (d.top_speed * share / 100.0)


def _share(value: object, limit: float) -> float:
    """The speed share a request asks for, within (0, limit] percent (an unreadable one: the limit)."""
    try:
        share = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return limit
    return min(share, limit) if math.isfinite(share) and share > 0 else limit
