"""``pnp sim up --serve-lds`` and ``pnp discover --lds`` / ``pnp run --cell`` with ``PNP_LDS``, as separate
processes, as a user runs them: the controller finds the OPC UA devices through the LDS alone."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from plugnproduce import service
from plugnproduce.protocols.upnp import private_network
from tests.lines import WAIT
from tests.processes import started, stop

CELL = str(service.builtin("cells", "mixed.yaml"))
TASK = str(service.builtin("tasks", "pick-and-screw.yaml"))
OPCUA = ["binpicking-pc-ua", "screwdriver-ua"]


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "plugnproduce", *args]


def test_discover_and_run_find_the_opc_ua_devices_through_the_lds_sim_up_serves(tmp_path: Path) -> None:
    devices_env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    with log.open("w") as out, started(command("sim", "up", CELL, "--serve-lds", "0", "--state-file", str(state)),
                                       env=devices_env, stdout=out, stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists() or "is up" not in log.read_text():
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        printed = log.read_text()
        lds = re.search(r"^lds +opcua (opc\.tcp://127\.0\.0\.1:\d+)$", printed, re.M)
        assert lds is not None, printed
        elsewhere = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}  # no SSDP reaches the devices
        found = subprocess.run(command("discover", "--json", "--lds", lds.group(1), "--expect", "2",
                                       "--timeout", "3600"), env=elsewhere, capture_output=True, text=True,
                               timeout=10 * WAIT)
        journal = tmp_path / "run.jsonl"
        ran = subprocess.run(command("run", TASK, "--cell", CELL, "--json", "--journal", str(journal)),
                             env={**devices_env, "PNP_LDS": lds.group(1)}, capture_output=True, text=True,
                             timeout=10 * WAIT)
        assert stop(up, signal.SIGINT) == 0, log.read_text()
    assert found.returncode == 0, found.stdout + found.stderr
    listed = json.loads(found.stdout)
    assert sorted(d["id"] for d in listed["devices"]) == OPCUA
    endpoints = {d["id"]: d["endpoint"] for d in listed["devices"]}
    for device in OPCUA:
        assert re.search(rf"^{device} +opcua {re.escape(endpoints[device])}$", printed, re.M), (endpoints, printed)
    assert ran.returncode == 0, ran.stdout + ran.stderr
    assert json.loads(ran.stdout)["outcome"] == "succeeded"
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    assert sorted(next(r["devices"] for r in records if "devices" in r)) == sorted(
        ["robot", "gripper", "sensor3d", *OPCUA])


def test_a_bad_lds_is_one_line_and_exit_2(tmp_path: Path) -> None:
    told = subprocess.run(command("discover", "--lds", "http://127.0.0.1:4840"), capture_output=True, text=True,
                          timeout=10 * WAIT)
    assert told.returncode == 2, told.stdout + told.stderr
    assert told.stderr.strip().splitlines() == [
        "error: OPC UA endpoint 'http://127.0.0.1:4840' is not opc.tcp://HOST:PORT[/PATH]"], told.stderr


def test_sim_up_with_an_lds_that_is_not_there_is_one_line_and_exit_2(tmp_path: Path) -> None:
    with socket.socket() as sock:  # a port nothing listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
        told = subprocess.run(command("sim", "up", CELL, "--lds", f"opc.tcp://127.0.0.1:{port}", "--state-file",
                                      str(tmp_path / "control.json")),
                              env={**os.environ, "PNP_SSDP_PORT": str(private_network().port)}, capture_output=True,
                              text=True, timeout=10 * WAIT)
    assert told.returncode == 2, told.stdout + told.stderr
    lines = told.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"error: device binpicking-pc-ua: cannot register with the Local Discovery Server opc.tcp://127.0.0.1:{port}: "
    ), told.stderr
    assert not (tmp_path / "control.json").exists()
