"""``pnp sim up``, ``pnp discover`` and ``pnp sim plug/unplug`` as separate processes, as a user runs them."""

from __future__ import annotations

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
from plugnproduce.protocols.upnp import private_network
from tests.lines import WAIT, Lines
from tests.processes import started, stop

CELL = str(service.builtin("cells", "bin-picking.yaml"))


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "plugnproduce", *args]


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}


@pytest.fixture
def simulated_cell(env: dict[str, str], tmp_path: Path) -> Iterator[Path]:
    state = tmp_path / "control.json"
    log = tmp_path / "sim.log"
    with log.open("w") as out, started(command("sim", "up", CELL, "--state-file", str(state)), env=env, stdout=out,
                                       stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists():  # polling a file the process writes once its devices are announced
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        yield state
        assert stop(up, signal.SIGINT) == 0, log.read_text()  # Ctrl-C; a fully loaded machine stops it late
    assert "stopped" in log.read_text()


def test_discover_lists_the_four_devices(simulated_cell: Path, env: dict[str, str]) -> None:
    """The search ends once the four expected devices have answered (a busy machine answers late), under the
    suite's limit: not at the end of its window (an hour), nor at a fixed shorter one."""
    search = command("discover", "--json", "--timeout", "3600", "--expect", "4")
    result = subprocess.run(search, env=env, capture_output=True, text=True, timeout=2 * WAIT)
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout)
    assert sorted(d["id"] for d in found["devices"]) == ["binpicking-pc", "gripper", "robot", "sensor3d"]
    assert "pick" in found["offered"]


def test_unplugging_the_gripper_removes_pick_and_plugging_brings_it_back(
        simulated_cell: Path, env: dict[str, str]) -> None:
    watch = subprocess.Popen(command("discover", "--json", "--watch", "--timeout", "10"), env=env, text=True,
                             stdout=subprocess.PIPE)
    lines = Lines(watch.stdout)
    try:
        seen = json.loads(lines.next())
        while "pick" not in seen["offered"]:  # on a busy machine a device may answer after the first search
            seen = json.loads(lines.next())
            assert seen["change"] == "plug", seen
        state = json.loads(simulated_cell.read_text())
        control = ["--control", f"{state['host']}:{state['port']}"]
        subprocess.run(command("sim", "unplug", "gripper", *control), env=env, check=True, timeout=60,
                       capture_output=True)
        change = json.loads(lines.next())
        assert (change["change"], change["device"]) == ("unplug", "gripper")
        assert "pick" not in change["offered"] and "bin-pick" not in change["offered"]
        subprocess.run(command("sim", "plug", "gripper", *control), env=env, check=True, timeout=60,
                       capture_output=True)
        change = json.loads(lines.next())
        assert (change["change"], change["device"]) == ("plug", "gripper")
        assert "pick" in change["offered"]
    finally:
        stop(watch)
        lines.rest()
        assert watch.stdout is not None
        watch.stdout.close()
