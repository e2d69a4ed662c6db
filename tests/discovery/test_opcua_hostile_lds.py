"""A hostile Local Discovery Server: a real asyncua server that tells the controller it takes messages of any size
and answers FindServers with megabytes. The connection that asks it is held to the same limit as a device's
(16 chunks of 64 KiB), so the answer ends the connection and is never parsed; the LDS is refused in one line
naming it, and discovery of the others (by SSDP) goes on."""

from __future__ import annotations

import asyncio
import json
import os
import sys
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import pytest
from asyncua import Server, ua
from asyncua.common.connection import TransportLimits

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.discovery import LiveCell
from plugnproduce.errors import ProtocolError
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua.discovery import find_servers
from plugnproduce.protocols.opcua.spec import MAX_MESSAGE, format_endpoint
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT

SERVERS = 200
"""Servers the hostile LDS lists: fewer than the controller's count limit, each with 12 KB of discovery URLs."""


class _Boundless(TransportLimits):  # type: ignore[misc]
    """Acknowledges any client with "no limits" and then sends whatever it has, whatever the client asked for."""

    def create_acknowledge_and_set_limits(self, msg: ua.Hello) -> ua.Acknowledge:
        ack = super().create_acknowledge_and_set_limits(msg)
        ack.MaxMessageSize = ack.MaxChunkCount = 0
        self.max_message_size = self.max_chunk_count = 0
        return ack


@pytest.fixture
async def hostile_lds() -> AsyncIterator[str]:
    """An LDS whose FindServers answer is about 2.4 MB: 200 servers of the device naming rule, 60 long URLs each."""
    server = Server()
    await server.init()
    server.limits = _Boundless()
    server.set_endpoint(format_endpoint("127.0.0.1", 0))
    server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
    for n in range(SERVERS):
        registered = ua.RegisteredServer(ServerUri=f"urn:plugnproduce:device:flood{n}",
                                         ServerNames=[ua.LocalizedText("flood")], IsOnline=True,
                                         DiscoveryUrls=[f"opc.tcp://127.0.0.1:1/{'x' * 200}{k}" for k in range(60)])
        server.iserver.register_server(registered)
    await server.start()
    port = server.bserver._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
    try:
        yield format_endpoint("127.0.0.1", port)
    finally:
        await server.stop()


async def test_a_findservers_answer_beyond_the_message_limit_is_refused_naming_the_lds(hostile_lds: str) -> None:
    with pytest.raises(ProtocolError) as refused:
        await find_servers(hostile_lds, WAIT)
    said = str(refused.value)
    assert said.startswith(f"Local Discovery Server {hostile_lds}: its FindServers answer is larger than "
                           f"{MAX_MESSAGE >> 20} MiB"), said
    assert "\n" not in said


def _device(name: str) -> Any:
    return load_device(Path(service.builtin("devices", f"{name}.ttl")), load_taxonomy())


async def test_discovery_goes_on_beside_a_hostile_lds(hostile_lds: str) -> None:
    """The live cell names the LDS among the refused, and finds the device that answers SSDP all the same."""
    network = private_network()
    async with SimulatedDevice(_device("gripper"), network=network) as gripper, \
            LiveCell(load_taxonomy(), network=network, lds=hostile_lds, search_timeout=WAIT,
                     expected=["gripper"]) as live:
        assert [(d.id, d.endpoint) for d in live.cell.devices] == [("gripper", gripper.endpoint)]
        refusal = live.refused[hostile_lds]
    assert refusal.location == hostile_lds
    assert refusal.reason.startswith(f"Local Discovery Server {hostile_lds}: its FindServers answer is larger")


async def test_pnp_discover_says_the_refused_lds_in_one_line_and_lists_the_others(hostile_lds: str) -> None:
    network = private_network()
    env = {**os.environ, "PNP_SSDP_PORT": str(network.port)}
    async with SimulatedDevice(_device("gripper"), network=network):
        proc = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "plugnproduce", "discover", "--lds", hostile_lds, "--expect", "1",
            "--timeout", "3600", env=env, stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
        out, err = await asyncio.wait_for(proc.communicate(), 10 * WAIT)
    assert proc.returncode == 0, out.decode() + err.decode()
    lines = out.decode().splitlines()
    assert lines[0].split()[0] == "gripper", lines
    refused = [line for line in lines if line.startswith("refused")]
    assert refused == [f"refused Local Discovery Server {hostile_lds}: its FindServers answer is larger than "
                       f"{MAX_MESSAGE >> 20} MiB (at most 16 chunks of 64 KiB)"], lines
    assert err.decode() == ""

    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "plugnproduce", "discover", "--json", "--lds", hostile_lds, "--timeout", "0.5",
        "--settle", "0.2", env=env, stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
    out, err = await asyncio.wait_for(proc.communicate(), 10 * WAIT)
    assert proc.returncode == 0, out.decode() + err.decode()
    assert [r["url"] for r in json.loads(out)["refused"]] == [hostile_lds]


async def test_pnp_run_names_the_refused_lds_where_it_says_the_devices_missing(hostile_lds: str) -> None:
    """Before, an LDS that could not be asked ended the run's discovery at once; now the run waits for the
    cell's devices as always, and the line that says them missing names the LDS refused and why."""
    env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port), "PNP_LDS": hostile_lds}
    proc = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "plugnproduce", "run", str(service.builtin("tasks", "pick-and-screw.yaml")),
        "--cell", str(service.builtin("cells", "mixed.yaml")), "--discovery-timeout", "1", env=env,
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
    out, err = await asyncio.wait_for(proc.communicate(), 10 * WAIT)
    assert proc.returncode == 2, out.decode() + err.decode()
    assert err.decode().splitlines() == [
        "error: device(s) robot, gripper, sensor3d, binpicking-pc-ua, screwdriver-ua of the cell not found on the "
        f"network within 1 s; refused Local Discovery Server {hostile_lds}: its FindServers answer is larger than "
        f"{MAX_MESSAGE >> 20} MiB (at most 16 chunks of 64 KiB)"]


async def test_a_silent_lds_holds_up_nothing(tmp_path: Path) -> None:
    """An LDS that accepts the connection and never says a word is asked beside the search, as a device is
    read: the device answering SSDP is in the cell while the LDS has not been refused yet (before, discovery
    waited for the LDS's whole budget before it began)."""
    writers: list[asyncio.StreamWriter] = []

    async def mute(_reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        writers.append(writer)

    silent = await asyncio.start_server(mute, "127.0.0.1", 0)
    lds = format_endpoint("127.0.0.1", silent.sockets[0].getsockname()[1])
    network = private_network()
    try:
        async with SimulatedDevice(_device("gripper"), network=network), \
                LiveCell(load_taxonomy(), network=network, lds=lds, search_timeout=WAIT, expected=["gripper"],
                         device_budget=10 * WAIT) as live:
            assert [d.id for d in live.cell.devices] == ["gripper"]
            assert live.refused == {}  # the LDS is still being asked
            deadline = asyncio.get_running_loop().time() + WAIT
            while not writers:  # it was asked (its connection accepted)
                assert asyncio.get_running_loop().time() < deadline, "the LDS was never asked"
                await asyncio.sleep(0.05)
    finally:
        for writer in writers:
            writer.close()
        silent.close()
        await silent.wait_closed()
