"""Teach-in: a pose the simulated robot reports is read by its state query and held to its contracts."""

from __future__ import annotations

import asyncio
import json
import os
import sys
from pathlib import Path

import pytest

from plugnproduce import controller, service
from plugnproduce.errors import UnknownName
from plugnproduce.protocols import xirp
from plugnproduce.protocols.upnp import SsdpNetwork, private_network
from plugnproduce.sim.cell import SimulatedCell
from tests.lines import WAIT

CELL = service.builtin("cells", "bin-picking.yaml")
SHORT_ARM = Path(__file__).parent.parent / "data" / "libraries" / "short-arm"
GUIDED = [0.35, 0.15, 0.22, 0.0, 180.0, 45.0]


async def guide(sim: SimulatedCell, device: str, pose: list[float]) -> None:
    """What the operator's hand does: move the device to ``pose`` (straight over XIRP, not through pnp)."""
    client = await xirp.XirpClient.connect_endpoint(sim.devices[device].endpoint, timeout=WAIT)
    try:
        await client.request("MoveTo", {"TargetPose": pose, "Speed": 10}, timeout=WAIT)
        deadline = asyncio.get_running_loop().time() + WAIT
        while await client.state(timeout=WAIT) != "at_pose":
            assert asyncio.get_running_loop().time() < deadline, f"{device} did not reach the pose"
            await asyncio.sleep(0.02)
    finally:
        await client.close()


async def pnp(network: SsdpNetwork, *args: str) -> tuple[int, str, str]:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "plugnproduce", *args, "--discovery-timeout", str(WAIT),
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
        env={**os.environ, "PNP_SSDP_PORT": str(network.port)})
    out, err = await asyncio.wait_for(proc.communicate(), 3 * WAIT)
    return proc.returncode or 0, out.decode(), err.decode()


def test_teach_reads_the_pose_the_robot_was_guided_to(monkeypatch: pytest.MonkeyPatch) -> None:
    network = private_network()
    monkeypatch.setenv("PNP_SSDP_PORT", str(network.port))

    async def scenario() -> tuple[service.Taught, service.Taught, tuple[int, str, str]]:
        async with SimulatedCell(service.cell(CELL), network=network) as sim:
            before = await controller.teach("robot", "TargetPose", CELL, discovery_timeout=WAIT)
            await guide(sim, "robot", GUIDED)
            after = await controller.teach("robot", "TargetPose", CELL, discovery_timeout=WAIT)
            return before, after, await pnp(network, "teach", "robot", "TargetPose", "--cell", str(CELL), "--json")

    before, after, (code, out, err) = asyncio.run(scenario())
    assert before.value == [0.4, 0.0, 0.6, 0.0, 180.0, 0.0] and before.state == "home"  # the chart's home pose
    assert after.value == GUIDED and after.state == "at_pose" and after.accepted
    assert after.held_to == ("MoveTo TargetPose: Pose, reach 1.45 m",)
    assert code == 0, err
    assert json.loads(out) == {"device": "robot", "quantity": "TargetPose", "value": GUIDED, "unit": "",
                               "state": "at_pose", "accepted": True, "held_to": ["MoveTo TargetPose: Pose, reach 1.45 m"],
                               "refused": []}


def test_a_taught_pose_beyond_the_arm_s_reach_is_refused_with_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    """A library's arm reaching 0.5 m was left 0.72 m out: teach prints the pose and refuses it, exit 1."""
    network = private_network()
    cell = SHORT_ARM / "cells" / "short-arm.yaml"

    async def scenario() -> tuple[tuple[int, str, str], tuple[int, str, str]]:
        async with SimulatedCell(service.cell(cell, service.knowledge((SHORT_ARM,))), network=network) as sim:
            far = await pnp(network, "--library", str(SHORT_ARM), "teach", "short-arm", "TargetPose", "--cell",
                            str(cell))
            await guide(sim, "short-arm", GUIDED)
            near = await pnp(network, "--library", str(SHORT_ARM), "teach", "short-arm", "TargetPose", "--cell",
                             str(cell))
            return far, near

    (code, out, err), (near_code, near_out, _) = asyncio.run(scenario())
    assert code == 1
    assert out.splitlines() == ["short-arm TargetPose = [0.4, 0.0, 0.6, 0.0, 180.0, 0.0] (short-arm is home)"]
    assert err.splitlines() == ["refused: short-arm MoveTo TargetPose reaches at most 0.5 m from its base; "
                                "the pose is 0.721 m away"]
    assert near_code == 0 and "within MoveTo TargetPose: Pose, reach 0.5 m" in near_out


def test_a_quantity_the_device_does_not_report_is_bad_input_before_the_network_is_asked() -> None:
    with pytest.raises(UnknownName, match="unknown reported quantity 'TargetPos' of device robot; did you mean "
                                          "TargetPose"):
        asyncio.run(controller.teach("robot", "TargetPos", CELL, discovery_timeout=0.1))
