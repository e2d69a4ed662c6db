"""The simulated bin: seeded parts that the localiser reports, a grip takes out and an empty bin says so."""

from __future__ import annotations

import asyncio
import dataclasses
from collections.abc import Mapping
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.description.model import DeviceDescription
from plugnproduce.executor.links import open_link
from plugnproduce.protocols import upnp
from plugnproduce.sim.bin import BinError, SimulatedBin
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT


def device(name: str) -> DeviceDescription:
    return service.cell(service.builtin("cells", "bin-picking.yaml")).device(name)


def localize(parts: SimulatedBin) -> dict[str, Any]:
    datamodel: dict[str, Any] = {}
    parts.on_request(device("binpicking-pc"), {"PartType": "bracket"}, datamodel)
    return datamodel


def pick_at(parts: SimulatedBin, pose: list[float]) -> None:
    parts.on_request(device("robot"), {"TargetPose": pose, "Speed": 50}, {})
    parts.on_request(device("gripper"), {"GripForce": 40}, {})


def test_the_same_seed_places_the_same_parts_and_another_seed_others() -> None:
    assert [p.pose for p in SimulatedBin(5, seed=3).parts] == [p.pose for p in SimulatedBin(5, seed=3).parts]
    assert [p.pose for p in SimulatedBin(5, seed=3).parts] != [p.pose for p in SimulatedBin(5, seed=4).parts]


def test_each_localisation_reports_a_remaining_part_and_a_grip_there_takes_it_out() -> None:
    parts = SimulatedBin(3, seed=7)
    placed = [p.pose for p in parts.parts]
    reported = []
    for _ in range(3):
        found = localize(parts)
        assert found["outcome"] == "PartFound"
        reported.append(found["part_pose"])
        pick_at(parts, found["part_pose"])
    assert sorted(reported) == sorted(placed)
    assert parts.parts == [] and len(parts.taken) == 3
    assert localize(parts)["outcome"] == "BinEmpty"


def test_moving_into_the_bin_where_no_part_lies_is_refused() -> None:
    parts = SimulatedBin(2, seed=1)
    with pytest.raises(BinError, match="no part at pose 0.4 0.1 0.05 0 180 0 in the bin"):
        parts.on_request(device("robot"), {"TargetPose": [0.4, 0.1, 0.05, 0, 180, 0]}, {})
    parts.on_request(device("robot"), {"TargetPose": "0.6 -0.2 0.1 0 180 0"}, {})  # outside the bin: fine
    assert len(parts.parts) == 2


def test_a_grip_away_from_every_part_takes_nothing() -> None:
    parts = SimulatedBin(2, seed=1)
    pick_at(parts, [0.6, -0.2, 0.1, 0, 180, 0])
    assert len(parts.parts) == 2 and parts.held is None


async def test_the_localised_pose_comes_back_over_upnp_as_the_event_values() -> None:
    parts = SimulatedBin(4, seed=11)
    events: asyncio.Queue[tuple[str, Mapping[str, Any]]] = asyncio.Queue()
    network = upnp.private_network()
    pc = device("binpicking-pc")
    async with SimulatedDevice(pc, network=network, bin=parts) as simulated:
        live = dataclasses.replace(pc, endpoint=simulated.endpoint)
        link = await open_link(live, lambda _d, name, params: events.put_nowait((name, params)),
                               lambda *_: None, lambda *_: None)
        try:
            await link.request("Localize", {"PartType": "bracket"}, WAIT)
            name, params = await asyncio.wait_for(events.get(), WAIT)
        finally:
            await link.close()
    top = max((p for p in SimulatedBin(4, seed=11).parts), key=lambda p: p.pose[2])
    assert name == "PartLocalized"
    assert params == {"outcome": "PartFound", "part_pose": top.pose, "part_type": "bracket"}
