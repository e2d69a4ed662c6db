"""``pnp sim up`` on the mixed cell prints each OPC UA device's endpoint, and ``pnp run --cell`` runs the mixed
task against it, as separate processes, as a user runs them."""

from __future__ import annotations

import json
import os
import re
import signal
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


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "plugnproduce", *args]


def test_sim_up_prints_opc_tcp_endpoints_and_run_cell_runs_the_mixed_task(tmp_path: Path) -> None:
    env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port)}
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    with log.open("w") as out, started(command("sim", "up", CELL, "--state-file", str(state)), env=env, stdout=out,
                                       stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists() or "is up" not in log.read_text():  # it writes both once its devices are announced
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        printed = log.read_text()
        for device in ("binpicking-pc-ua", "screwdriver-ua"):
            assert re.search(rf"^{device} +opcua opc\.tcp://127\.0\.0\.1:\d+/pnp/{device}$", printed, re.M), printed
        assert re.search(r"^robot +xirp +xirp://127\.0\.0\.1:\d+$", printed, re.M), printed
        journal = tmp_path / "run.jsonl"
        run = subprocess.run(command("run", TASK, "--cell", CELL, "--json", "--journal", str(journal)), env=env,
                             capture_output=True, text=True, timeout=10 * WAIT)
        assert stop(up, signal.SIGINT) == 0, log.read_text()
    assert run.returncode == 0, run.stdout + run.stderr
    assert json.loads(run.stdout)["outcome"] == "succeeded"
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    screwing = [r["event"] for r in records if r["kind"] == "event" and r["device"] == "screwdriver-ua"]
    assert screwing == ["Completed", "Completed"]
