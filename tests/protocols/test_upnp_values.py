"""Argument values on the wire, pinned to the table of docs/upnp.md: what the executor sends for each datatype,
and a simulated UPnP device reading them as strictly as the datatype says (a pose joined with commas is refused)."""

from __future__ import annotations

import dataclasses
import json
import re
import socket
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.errors import RemoteError
from plugnproduce.executor.links import UpnpLink
from plugnproduce.protocols import upnp
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT

DOC = Path(__file__).parents[2] / "docs" / "upnp.md"
DATATYPE = {"xsd:decimal": "decimal", "xsd:integer": "integer", "xsd:boolean": "boolean", "xsd:string": "string",
            "pnp:Pose": "Pose"}


def table() -> list[tuple[str, Any, str, str | None]]:
    """The rows of "Argument values on the wire": (datatype, value, text on the wire, a text refused)."""
    text = DOC.read_text(encoding="utf-8").split("### Argument values on the wire", 1)[1]
    rows = []
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 5 and cells[0].startswith("`") and cells[0].strip("`") in DATATYPE:
            datatype, _, value, wire, refused = (c.strip("`") for c in cells)
            rows.append((DATATYPE[datatype], json.loads(value), wire, refused or None))
        elif rows and not line.startswith("|"):
            break
    return rows


ROWS = table()


def test_the_table_names_every_datatype_an_argument_can_have() -> None:
    assert {r[0] for r in ROWS} == set(DATATYPE.values())


@pytest.mark.parametrize(("datatype", "value", "wire", "refused"), ROWS, ids=[f"{r[0]}:{r[2]}" for r in ROWS])
def test_a_value_is_written_and_read_back_as_the_table_says(datatype: str, value: Any, wire: str,
                                                            refused: str | None) -> None:
    assert upnp.lexical(value) == wire
    assert upnp.parse_lexical(wire, datatype) == value
    if refused is not None:
        with pytest.raises(ValueError, match="^'.*' is not"):
            upnp.parse_lexical(refused, datatype)


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@pytest.fixture
def network() -> upnp.SsdpNetwork:
    return upnp.SsdpNetwork(port=free_udp_port())


def scara() -> service.DeviceDescription:
    return next(d for d in service.catalogue() if d.id == "scara")  # a UPnP robot: MoveTo(TargetPose, Speed)


async def test_the_executor_sends_every_datatype_as_the_table_says(network: upnp.SsdpNetwork) -> None:
    names = [f"A{n}" for n in range(len(ROWS))]
    received: list[dict[str, Any]] = []

    async def handler(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        received.append(dict(arguments))
        return {"Result": "accepted"}

    spec = upnp.with_state_query(upnp.service_spec_from_chart_events({"Go": names}, []))
    async with upnp.UpnpDeviceServer("scara", "Recording robot", upnp.device_type_for("Robot"), spec, handler,
                                     network=network) as server:
        device = dataclasses.replace(scara(), endpoint=server.location or "", command_timeout=WAIT)
        link = await UpnpLink.open(device, lambda *_: None, lambda *_: None, lambda *_: None)
        try:
            await link.request("Go", dict(zip(names, (r[1] for r in ROWS), strict=True)), WAIT)
        finally:
            await link.close()
    assert received == [dict(zip(names, (r[2] for r in ROWS), strict=True))]


POSE = [0.4, 0.1, 0.05, 0, 180, 0]


async def test_a_simulated_device_takes_a_pose_one_space_apart(network: upnp.SsdpNetwork) -> None:
    async with SimulatedDevice(scara(), network=network) as robot:
        device = dataclasses.replace(scara(), endpoint=robot.endpoint, command_timeout=WAIT)
        link = await UpnpLink.open(device, lambda *_: None, lambda *_: None, lambda *_: None)
        try:
            await link.request("MoveTo", {"TargetPose": POSE, "Speed": 50}, WAIT)
        finally:
            await link.close()
        assert robot.state == "moving"


@pytest.mark.parametrize(("argument", "text", "why"), [
    ("TargetPose", "0.4,0.1,0.05,0,180,0", "is not a pose; expected six decimals separated by one space"),
    ("TargetPose", "0.4 0.1 0.05 0 180", "is not a pose"),
    ("TargetPose", "[0.4, 0.1, 0.05, 0, 180, 0]", "is not a pose"),
    ("Speed", "5e1", "is not a decimal"),
    ("Speed", "50 %", "is not a decimal"),
])
async def test_a_simulated_device_refuses_an_argument_not_in_its_datatypes_form(
        network: upnp.SsdpNetwork, argument: str, text: str, why: str) -> None:
    arguments = {"TargetPose": " ".join(str(v) for v in POSE), "Speed": "50", argument: text}
    async with SimulatedDevice(scara(), network=network) as robot:
        async with await upnp.UpnpDeviceClient.connect(robot.endpoint, "127.0.0.1", timeout=WAIT) as client:
            with pytest.raises(RemoteError) as refused:
                await client.invoke("MoveTo", arguments)
        assert robot.state == "home"  # the chart did not move
    message = str(refused.value)
    assert "UPnP error 600" in message and f"MoveTo argument {argument}: " in message
    assert re.search(re.escape(why), message), message
