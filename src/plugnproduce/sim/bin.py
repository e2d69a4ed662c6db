"""The simulated bin: N parts at seeded random poses that the simulated devices see, pick and place.

The bin is the world the simulated devices share. A device that can localise parts
reports the pose and type of a part still in the bin (into its chart's ``outcome``
(``PartFound``), ``part_pose`` and ``part_type`` variables, which its event carries);
with the bin empty its outcome is ``BinEmpty`` and the pose stays the last one. A robot
moving into the bin to where no part lies is refused with a fault that says so. A
gripper that grips (a request carrying a grip force) while the robot is at a part's pose
takes that part out of the bin; its other requests let it go (placed). The same seed
gives the same bin.
"""

from __future__ import annotations

import math
import random
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from plugnproduce.description.model import DeviceDescription
from plugnproduce.errors import PlugNProduceError
from plugnproduce.ontology.iris import local_name

AREA = ((0.30, 0.50), (0.00, 0.20))
"""The bin's floor: x and y ranges in metres."""
DEPTH = 0.10
"""A pose below this height (m) and over the floor is inside the bin."""
TOLERANCE = 0.001
"""How far (m) a pose may lie from a part's pose and still reach it."""
MAX_PARTS = 10_000


@dataclass
class Part:
    """One part in the bin."""

    number: int
    pose: list[float]
    """x y z (m) rx ry rz (deg)."""
    type: str


class BinError(PlugNProduceError, LookupError):
    """A request the bin cannot let happen (no part where the robot goes)."""


class SimulatedBin:
    """A seeded bin of parts; :meth:`on_request` is called with each request a simulated device accepts."""

    def __init__(self, parts: int, seed: int = 0, part_type: str = "bracket") -> None:
        if not 0 <= parts <= MAX_PARTS:
            raise ValueError(f"a simulated bin holds 0 to {MAX_PARTS} parts; asked for {parts}")
        rng = random.Random(seed)
        self.parts = [Part(i + 1, _random_pose(rng), part_type) for i in range(parts)]
        self.taken: list[Part] = []
        self.held: Part | None = None
        self.robot_pose: list[float] | None = None

    def on_request(self, device: DeviceDescription, params: Mapping[str, Any],
                   datamodel: dict[str, Any]) -> None:
        """Let a device's request (with ``params``) act on the bin; ``datamodel`` is the device chart's.

        Raises :class:`BinError` for a request the bin cannot let happen.
        """
        skills = {local_name(s) for s in device.skills}
        pose = _pose(params.get("TargetPose"))
        if "CanLocalizeParts" in skills:
            self._localize(datamodel)
        elif pose is not None and "CanMove" in skills:
            self._move(pose)
        elif "CanGrip" in skills and "GripForce" in params:
            self._close()
        elif "CanGrip" in skills:
            self.held = None

    def _localize(self, datamodel: dict[str, Any]) -> None:
        if not self.parts:
            datamodel["outcome"] = "BinEmpty"
            return
        part = max(self.parts, key=lambda p: p.pose[2])  # the one on top
        datamodel["outcome"], datamodel["part_pose"], datamodel["part_type"] = "PartFound", list(part.pose), part.type

    def _move(self, pose: list[float]) -> None:
        if _in_bin(pose) and self._part_at(pose) is None:
            raise BinError(f"no part at pose {' '.join(format(v, 'g') for v in pose)} in the bin "
                           f"({len(self.parts)} part(s) left)")
        self.robot_pose = pose

    def _close(self) -> None:
        part = self._part_at(self.robot_pose) if self.robot_pose is not None else None
        if part is not None:
            self.parts.remove(part)
            self.taken.append(part)
            self.held = part

    def _part_at(self, pose: list[float]) -> Part | None:
        for part in self.parts:
            if math.dist(part.pose[:3], pose[:3]) <= TOLERANCE:
                return part
        return None


def _random_pose(rng: random.Random) -> list[float]:
    (x0, x1), (y0, y1) = AREA
    return [round(rng.uniform(x0 + 0.02, x1 - 0.02), 3), round(rng.uniform(y0 + 0.02, y1 - 0.02), 3),
            round(rng.uniform(0.02, DEPTH - 0.02), 3), 0.0, 180.0, round(rng.uniform(-180.0, 180.0), 1)]


def _in_bin(pose: list[float]) -> bool:
    (x0, x1), (y0, y1) = AREA
    return x0 <= pose[0] <= x1 and y0 <= pose[1] <= y1 and pose[2] < DEPTH


def _pose(value: object) -> list[float] | None:
    """A pose as six numbers, from a list or its lexical form; None if it is none."""
    items = value.split() if isinstance(value, str) else value
    if not isinstance(items, list | tuple) or len(items) != 6:
        return None
    try:
        return [float(v) for v in items]
    except (TypeError, ValueError):
        return None
