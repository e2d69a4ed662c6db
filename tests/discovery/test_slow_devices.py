"""One slow or hostile device costs only itself: discovery reads every device beside the others, each within its
own time and size budget, and says which it refused, where and why."""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.discovery import LiveCell
from plugnproduce.protocols.upnp import SsdpNetwork, private_network
from tests.discovery.hostile import HostileDevice
from tests.discovery.test_live_cell import free_udp_port, sensor_server

CELL = str(service.builtin("cells", "bin-picking.yaml"))
PICK_AND_PLACE = str(service.builtin("tasks", "pick-and-place.yaml"))
WAIT = 60.0  # a fully loaded machine answers late; never a measure of speed


@contextlib.contextmanager
def hostile_devices(network: SsdpNetwork, *kinds: str) -> Iterator[list[HostileDevice]]:
    with contextlib.ExitStack() as stack:
        yield [stack.enter_context(HostileDevice(network, f"uuid:hostile-{kind}-{i}", kind))  # type: ignore[arg-type]
               for i, kind in enumerate(kinds)]


async def test_issue_24_an_honest_device_is_plugged_while_hanging_trickling_and_huge_ones_are_still_read(
        taxonomy) -> None:
    # each device's description was read in turn: the honest device waited behind every hostile one
    network = SsdpNetwork(port=free_udp_port())
    async with LiveCell(taxonomy, network=network, search_timeout=0.1, device_budget=30.0) as live:
        with hostile_devices(network, "hang", "slowloris", "huge") as hostile:  # each announces itself first
            async with sensor_server(network):
                before = []
                while (change := await live.next_change(WAIT)).kind != "plug":
                    before.append(change.device)
                assert change.device == "sensor3d"
                assert before in ([], [hostile[2].udn])  # while the hanging and trickling ones are still read
                async with asyncio.timeout(WAIT):
                    while set(live.refused) != {h.udn for h in hostile}:
                        await live.next_change()
    for device in hostile:
        refusal = live.refused[device.udn]
        assert refusal.location == device.location
        assert "\n" not in refusal.reason and device.udn in refusal.reason
    assert "4194304 bytes" in live.refused["uuid:hostile-huge-2"].reason  # read no further than the limit


async def test_a_device_refused_for_its_time_budget_is_read_again_on_its_next_announcement(taxonomy) -> None:
    network = SsdpNetwork(port=free_udp_port())
    async with LiveCell(taxonomy, network=network, search_timeout=0.1, device_budget=1.0) as live:
        with HostileDevice(network, "uuid:slow-then-fine", "hang") as device:
            refused = await live.next_change(WAIT)
            assert (refused.kind, refused.device) == ("refused", device.udn)
            assert "within 1 s" in refused.reason
            assert device.requests == 1
            device.announce()  # a loaded device answers in time the second time: here, it is asked again
            again = await live.next_change(WAIT)
            assert (again.kind, again.device) == ("refused", device.udn)
            assert device.requests == 2


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return {**os.environ, "PNP_SSDP_PORT": str(private_network().port), "PNP_RUNS": str(tmp_path / "runs")}


@pytest.fixture
def simulated_cell(env: dict[str, str], tmp_path: Path) -> Iterator[SsdpNetwork]:
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    with log.open("w") as out:
        up = subprocess.Popen([sys.executable, "-m", "plugnproduce", "sim", "up", CELL, "--state-file", str(state)],
                              env=env, stdout=out, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + WAIT
    while not state.exists():
        assert up.poll() is None, log.read_text()
        assert time.monotonic() < deadline, "pnp sim up did not come up"
        time.sleep(0.05)
    yield SsdpNetwork(port=int(env["PNP_SSDP_PORT"]))
    up.send_signal(signal.SIGINT)
    assert up.wait(timeout=WAIT) == 0, log.read_text()


def pnp(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          timeout=300, env=env)


def test_issue_24_a_hanging_device_beside_the_cell_leaves_the_run_on_the_four_honest_ones(
        simulated_cell: SsdpNetwork, env: dict[str, str]) -> None:
    # discovery read each device's description in turn: the hanging one, answering first, used the whole
    # search window, and the run waited in vain for the four honest ones
    with hostile_devices(simulated_cell, "hang"):
        done = pnp(env, "run", PICK_AND_PLACE, "--cell", CELL, "--discovery-timeout", "60")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "succeeded" in done.stdout


def test_discover_lists_the_honest_devices_and_every_refused_one_with_its_url_and_reason(
        simulated_cell: SsdpNetwork, env: dict[str, str]) -> None:
    with hostile_devices(simulated_cell, "hang", "slowloris", "huge") as hostile:
        as_json = pnp(env, "discover", "--json", "--timeout", "120")
        as_text = pnp(env, "discover", "--timeout", "120")
    assert as_json.returncode == 0, as_json.stderr
    found = json.loads(as_json.stdout)
    assert sorted(d["id"] for d in found["devices"]) == ["binpicking-pc", "gripper", "robot", "sensor3d"]
    assert {(r["udn"], r["url"]) for r in found["refused"]} == {(h.udn, h.location) for h in hostile}
    assert all(r["reason"] for r in found["refused"])
    assert as_text.returncode == 0, as_text.stderr
    for device in hostile:
        line = next(x for x in as_text.stdout.splitlines() if x.startswith(f"refused {device.udn} "))
        assert line.startswith(f"refused {device.udn} at {device.location}: ")


async def test_the_refused_devices_kept_are_the_latest_hundred_whatever_is_announced(taxonomy) -> None:
    from plugnproduce.discovery.live import MAX_REFUSED
    from tests.discovery.test_live_cell import squatter_alive

    network = SsdpNetwork(port=free_udp_port())
    nobody = f"http://127.0.0.1:{free_udp_port()}/description.xml"  # refused at once: nothing listens there
    async with LiveCell(taxonomy, network=network, search_timeout=0.1) as live:
        udns = [f"uuid:flood-{i}" for i in range(MAX_REFUSED + 50)]
        for udn in udns:
            squatter_alive(network, udn, nobody)
        seen = set()
        async with asyncio.timeout(WAIT):
            while len(seen) < len(udns):
                change = await live.next_change()
                seen.add(change.device)
        assert len(live.refused) == MAX_REFUSED
        assert all(r.location == nobody for r in live.refused.values())
