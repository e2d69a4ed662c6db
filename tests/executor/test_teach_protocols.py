"""Teach-in over UPnP and OPC UA: each protocol's state query carries the pose, held to the arm's contract.

The short-arm library (outside the package) has the same 0.5 m arm over XIRP, UPnP and OPC UA. It was left
stretched out 0.72 m from its base; the operator then guides it (here: straight over its own protocol, with a
UPnP client and a plain asyncua client, not through pnp) to a pose within reach.
"""

from __future__ import annotations

import asyncio
import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Awaitable, Callable, Mapping
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, ua

from plugnproduce import controller, service
from plugnproduce.description.model import DeviceDescription
from plugnproduce.errors import ProtocolError
from plugnproduce.protocols import upnp
from plugnproduce.protocols.opcua import NodeSpec, OpcUaDeviceServer, namespace_for
from plugnproduce.protocols.upnp import SsdpNetwork, private_network
from plugnproduce.sim.cell import SimulatedCell
from tests.lines import WAIT
from tests.processes import started, stop

SHORT_ARM = Path(__file__).parent.parent / "data" / "libraries" / "short-arm"
CELL = SHORT_ARM / "cells" / "short-arms.yaml"
MIXED = service.builtin("cells", "mixed.yaml")
GUIDED = [0.35, 0.15, 0.22, 0.0, 180.0, 45.0]
HOME = [0.4, 0.0, 0.6, 0.0, 180.0, 0.0]


async def until_at_pose(state: Callable[[], Awaitable[str]], device: str) -> None:
    deadline = asyncio.get_running_loop().time() + WAIT
    while await state() != "at_pose":
        assert asyncio.get_running_loop().time() < deadline, f"{device} did not reach the pose"
        await asyncio.sleep(0.02)


async def guide_over_upnp(location: str, pose: list[float]) -> None:
    """The operator's hand: MoveTo as a UPnP action (the pose in its lexical form), then wait for the arm."""
    client = await upnp.UpnpDeviceClient.connect(location, "127.0.0.1", timeout=WAIT)
    try:
        await client.invoke("MoveTo", {"TargetPose": upnp.lexical(pose)}, timeout=WAIT)

        async def state() -> str:
            return str((await client.invoke(upnp.STATE_ACTION, {}, timeout=WAIT))[upnp.STATE_ARGUMENT])

        await until_at_pose(state, "short-arm-upnp")
    finally:
        await client.close()


async def guide_over_opcua(endpoint: str, device: str, pose: list[float]) -> list[float]:
    """The same with a plain asyncua client: call MoveTo, wait for the arm; the pose a plain client reads from the
    arm's ``TargetPose`` variable."""
    async with Client(endpoint, timeout=WAIT) as client:
        ns = await client.get_namespace_index(namespace_for(device))
        arm = await client.nodes.objects.get_child(f"{ns}:{device}")
        await arm.call_method(f"{ns}:MoveTo", ua.Variant(pose, ua.VariantType.Double))
        state_node = await arm.get_child(f"{ns}:State")

        async def state() -> str:
            return str(await state_node.read_value())

        await until_at_pose(state, device)
        return list(await (await arm.get_child(f"{ns}:TargetPose")).read_value())


async def pnp(network: SsdpNetwork, *args: str) -> tuple[int, str, str]:
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "plugnproduce", "--library", str(SHORT_ARM), "teach", *args, "--cell", str(CELL),
        "--discovery-timeout", str(WAIT), stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE,
        env={**os.environ, "PNP_SSDP_PORT": str(network.port)})
    out, err = await asyncio.wait_for(proc.communicate(), 3 * WAIT)
    return proc.returncode or 0, out.decode(), err.decode()


Answer = tuple[int, str, str]


def test_teach_reads_the_pose_over_upnp_and_opcua_and_refuses_one_beyond_the_reach() -> None:
    network = private_network()

    async def scenario() -> tuple[list[Answer], list[Answer], list[float]]:
        async with SimulatedCell(service.cell(CELL, service.knowledge((SHORT_ARM,))), network=network) as sim:
            far = await asyncio.gather(pnp(network, "short-arm-upnp", "TargetPose"),
                                       pnp(network, "short-arm-ua", "TargetPose"))
            await guide_over_upnp(sim.devices["short-arm-upnp"].endpoint, GUIDED)
            read_by_asyncua = await guide_over_opcua(sim.devices["short-arm-ua"].endpoint, "short-arm-ua", GUIDED)
            near = await asyncio.gather(pnp(network, "short-arm-upnp", "TargetPose", "--json"),
                                        pnp(network, "short-arm-ua", "TargetPose", "--json"))
            return list(far), list(near), read_by_asyncua

    far, near, read_by_asyncua = asyncio.run(scenario())
    for device, (code, out, err) in zip(("short-arm-upnp", "short-arm-ua"), far, strict=True):
        assert code == 1, err
        assert out.splitlines() == [f"{device} TargetPose = {HOME} ({device} is home)"]
        assert err.splitlines() == [f"refused: {device} MoveTo TargetPose reaches at most 0.5 m from its base; "
                                    "the pose is 0.721 m away"]
    for device, (code, out, err) in zip(("short-arm-upnp", "short-arm-ua"), near, strict=True):
        assert code == 0, err
        assert json.loads(out) == {"device": device, "quantity": "TargetPose", "value": GUIDED, "unit": "",
                                   "state": "at_pose", "accepted": True,
                                   "held_to": ["MoveTo TargetPose: Pose, reach 0.5 m"], "refused": []}
    assert read_by_asyncua == GUIDED  # any OPC UA client reads it from the arm's variable


def test_a_device_whose_chart_reports_no_value_is_one_line_exit_2() -> None:
    """The mixed cell's UPnP 3D sensor and OPC UA nutrunner report nothing with their state: said before the
    network is asked."""
    for device, chart in (("sensor3d", "sensor3d.scxml"), ("screwdriver-ua", "screwdriver-ua.scxml")):
        result = subprocess.run([sys.executable, "-m", "plugnproduce", "teach", device, "TargetPose", "--cell",
                                 str(MIXED), "--discovery-timeout", "0.1"], capture_output=True, text=True,
                                timeout=3 * WAIT)
        assert result.returncode == 2
        assert result.stdout == ""
        assert result.stderr.splitlines() == [f"error: device {device} reports no value with its state: its chart "
                                              f"{chart} has no <data pnp:quantity=...>"]


def arm(device_id: str) -> DeviceDescription:
    return service.cell(CELL, service.knowledge((SHORT_ARM,))).device(device_id)


async def refuse(_request: str, _values: Mapping[str, Any]) -> Mapping[str, Any]:
    raise upnp.ActionFailed("a real device that takes nothing here", upnp.NOT_ACCEPTED_NOW)


def test_an_opcua_device_that_does_not_report_the_pose_its_description_promises_is_one_line() -> None:
    """A real device (a plain server without the ``TargetPose`` variable) behind the arm's description."""

    async def scenario() -> str:
        server = OpcUaDeviceServer(NodeSpec("short-arm-ua"), refuse, lambda: "home")
        await server.start()
        try:
            assert server.endpoint is not None
            with pytest.raises(ProtocolError) as caught:
                await controller.read_taught(dataclasses.replace(arm("short-arm-ua"), endpoint=server.endpoint),
                                             "TargetPose")
            return str(caught.value)
        finally:
            await server.stop()

    assert asyncio.run(scenario()) == ("device short-arm-ua did not report TargetPose with its state (it reported "
                                       "nothing but its state)")


def _upnp_teach_refusal(reports: list[str], state: Mapping[str, Any]) -> str:
    """What teaching ``TargetPose`` from a real UPnP arm says when its state query answers ``state``."""
    network = private_network()

    async def scenario() -> str:
        spec = upnp.with_state_query(upnp.service_spec_from_chart_events({"MoveTo": ["TargetPose"]}, []),
                                     reports=reports)

        async def answer(action: str, values: Mapping[str, Any]) -> Mapping[str, Any]:
            return state if action == upnp.STATE_ACTION else await refuse(action, values)

        async with upnp.UpnpDeviceServer("short-arm-upnp", "a plain arm", upnp.device_type_for("ArticulatedRobot"),
                                         spec, answer, network=network) as server:
            assert server.location is not None
            with pytest.raises(ProtocolError) as caught:
                await controller.read_taught(dataclasses.replace(arm("short-arm-upnp"), endpoint=server.location),
                                             "TargetPose")
            return str(caught.value)

    return asyncio.run(scenario())


def test_a_upnp_device_that_does_not_report_the_pose_its_description_promises_is_one_line() -> None:
    """A real device whose ``GetDeviceState`` answers its state only, behind the arm's description."""
    assert _upnp_teach_refusal([], {upnp.STATE_ARGUMENT: "home"}) == (
        "device short-arm-upnp did not report TargetPose with its state (it reported nothing but its state)")


def test_a_upnp_device_reporting_a_value_that_is_no_json_is_one_line() -> None:
    """A device whose state query answers ``TargetPose`` with text that is not JSON (an infinite number)."""
    assert _upnp_teach_refusal(["TargetPose"], {upnp.STATE_ARGUMENT: "home", "TargetPose": "[Infinity, 0, 0, 0, 180, 0]"}) \
        == "device short-arm-upnp: GetDeviceState: TargetPose is not a JSON value: '[Infinity, 0, 0, 0, 180, 0]'"



def test_teach_against_pnp_sim_up_as_separate_processes(tmp_path: Path) -> None:
    """``pnp sim up`` runs the library's arms; a plain asyncua client guides the OPC UA arm; ``pnp teach`` reads
    it (taken) and the UPnP arm, still stretched out (refused)."""
    env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    up_command = [sys.executable, "-m", "plugnproduce", "--library", str(SHORT_ARM), "sim", "up", str(CELL),
                  "--state-file", str(state)]
    teach = [sys.executable, "-m", "plugnproduce", "--library", str(SHORT_ARM), "teach"]
    with log.open("w") as out, started(up_command, env=env, stdout=out, stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists() or "is up" not in log.read_text():  # it writes both once its devices are announced
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        endpoint = re.search(r"^short-arm-ua +opcua (opc\.tcp://\S+)$", log.read_text(), re.M)
        assert endpoint is not None, log.read_text()
        asyncio.run(guide_over_opcua(endpoint.group(1), "short-arm-ua", GUIDED))
        ua_arm, upnp_arm = (subprocess.run([*teach, arm, "TargetPose", "--cell", str(CELL), "--discovery-timeout",
                                            str(WAIT)], env=env, capture_output=True, text=True, timeout=3 * WAIT)
                            for arm in ("short-arm-ua", "short-arm-upnp"))
        assert stop(up, signal.SIGINT) == 0, log.read_text()
    assert ua_arm.returncode == 0, ua_arm.stderr
    assert ua_arm.stdout.splitlines() == [f"short-arm-ua TargetPose = {GUIDED} (short-arm-ua is at_pose)",
                                          "within MoveTo TargetPose: Pose, reach 0.5 m"]
    assert upnp_arm.returncode == 1, upnp_arm.stderr
    assert upnp_arm.stderr.splitlines() == ["refused: short-arm-upnp MoveTo TargetPose reaches at most 0.5 m from "
                                            "its base; the pose is 0.721 m away"]
