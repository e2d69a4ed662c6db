"""The controller runs a Local Discovery Server of its own (``pnp discover --watch --serve-lds PORT``): OPC UA
devices started later (``pnp sim up --lds``) register with it and are plugged live, and unplugged when they stop.
Nothing but that LDS tells the controller of them (the devices announce themselves by SSDP on another private
port). The devices come from a library written outside the package (``opcua-glue``)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

from plugnproduce.protocols.upnp import private_network
from tests.lines import WAIT, Lines
from tests.processes import started, stop

GLUE = Path(__file__).parents[1] / "data" / "libraries" / "opcua-glue"
CELL = str(GLUE / "cells" / "opcua-glue-cell.yaml")


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "plugnproduce", *args]


def _until(lines: Lines, change: str, device: str) -> dict[str, Any]:
    """The next watch line that is ``change`` of ``device`` (refusals of the moment skipped)."""
    while True:
        line = json.loads(lines.next())
        if (line.get("change"), line.get("device")) == (change, device):
            return line


def test_devices_register_with_the_controllers_lds_and_plug_and_unplug_live(tmp_path: Path) -> None:
    controller_env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    devices_env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}  # no SSDP between the two
    with started(command("--library", str(GLUE), "discover", "--watch", "--json", "--serve-lds", "0",
                         "--timeout", "1", "--settle", "0.2"),
                 env=controller_env, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE) as watch:
        lines = Lines(watch.stdout)
        first = json.loads(lines.next())
        assert first["devices"] == [] and first["refused"] == [], first
        lds = first["lds"]
        assert lds.startswith("opc.tcp://127.0.0.1:"), first
        log, state = tmp_path / "sim.log", tmp_path / "control.json"
        with log.open("w") as out, started(command("sim", "up", CELL, "--lds", lds, "--state-file", str(state)),
                                           env=devices_env, stdout=out, stderr=subprocess.STDOUT) as up:
            plugged = _until(lines, "plug", "dispenser")
            assert plugged["devices"] == ["dispenser"]
            assert plugged["offered"] == ["lay-bead"], plugged
            assert stop(up, signal.SIGINT) == 0, log.read_text()
        unplugged = _until(lines, "unplug", "dispenser")
        assert unplugged["devices"] == []
        stop(watch)
        lines.rest()
        assert watch.stdout is not None and watch.stderr is not None
        watch.stdout.close()
        with watch.stderr:
            assert watch.stderr.read() == ""


def test_the_lds_line_comes_first_and_a_port_taken_is_one_line_and_exit_2() -> None:
    """In text the controller says where its LDS listens before it searches; a port it cannot listen on is
    said in one line, exit 2."""
    env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    shown = subprocess.run(command("discover", "--serve-lds", "0", "--timeout", "0.5", "--settle", "0.2"),
                           env=env, capture_output=True, text=True, timeout=10 * WAIT)
    assert shown.returncode == 0, shown.stderr
    first = shown.stdout.splitlines()[0].split()
    assert first[:2] == ["lds", "opcua"] and first[2].startswith("opc.tcp://127.0.0.1:"), shown.stdout

    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        told = subprocess.run(command("discover", "--serve-lds", str(port), "--timeout", "0.5"), env=env,
                              capture_output=True, text=True, timeout=10 * WAIT)
    assert told.returncode == 2, told.stdout + told.stderr
    assert told.stderr.splitlines() == [
        f"error: Local Discovery Server: cannot listen on opc.tcp://127.0.0.1:{port}: Address already in use"]

    both = subprocess.run(command("discover", "--serve-lds", "0", "--lds", "opc.tcp://127.0.0.1:4840"), env=env,
                          capture_output=True, text=True, timeout=10 * WAIT)
    assert both.returncode == 2 and len(both.stderr.splitlines()) == 1, both.stderr


def _cell_until(url: str, done: Any) -> dict[str, Any]:
    """The HMI's cell once ``done(cell)`` holds (polling the page's API, as the page does, under one limit)."""
    import time

    import httpx

    deadline = time.monotonic() + WAIT
    while not done(cell := httpx.get(url + "api/cell", timeout=WAIT).json()):
        assert time.monotonic() < deadline, cell
        time.sleep(0.1)
    return cell


def test_pnp_serve_runs_its_lds_and_shows_the_devices_that_register_and_leave(tmp_path: Path) -> None:
    controller_env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    devices_env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    with started(command("--library", str(GLUE), "serve", "--port", "0", "--serve-lds", "0"), env=controller_env,
                 text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE) as serve:
        lines = Lines(serve.stdout)
        url = lines.next().split()[-1]
        said = [lines.next().strip() for _ in range(3)]
        lds = said[-1].removeprefix("Local Discovery Server on ")
        assert lds.startswith("opc.tcp://127.0.0.1:"), said
        log, state = tmp_path / "sim.log", tmp_path / "control.json"
        with log.open("w") as out, started(command("sim", "up", CELL, "--lds", lds, "--state-file", str(state)),
                                           env=devices_env, stdout=out, stderr=subprocess.STDOUT) as up:
            cell = _cell_until(url, lambda c: c["devices"])
            assert [(d["id"], d["protocol"]) for d in cell["devices"]] == [("dispenser", "opcua")], cell
            assert stop(up, signal.SIGINT) == 0, log.read_text()
        _cell_until(url, lambda c: not c["devices"])
        assert stop(serve, signal.SIGINT) == 0
        lines.rest()
        assert serve.stdout is not None and serve.stderr is not None
        serve.stdout.close()
        with serve.stderr:
            assert "Traceback" not in serve.stderr.read()
