"""The mixed cell over SignAndEncrypt, as a user runs it: ``pnp sim up`` and ``pnp run --cell`` share one PKI
folder (``PNP_OPCUA_PKI``), which the simulated devices fill with the certificates; the task runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

from plugnproduce.protocols.upnp import private_network
from tests.lines import WAIT
from tests.processes import started, stop
from tests.sim.test_sim_opcua_cli import CELL, TASK, command


def test_the_mixed_task_runs_over_sign_and_encrypt_with_the_folders_certificates(tmp_path: Path) -> None:
    pki = tmp_path / "pki"
    env = {**os.environ, "PNP_SSDP_PORT": str(private_network().port), "PNP_OPCUA_PKI": str(pki),
           "PNP_OPCUA_SECURITY": "SignAndEncrypt"}
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    with log.open("w") as out, started(command("sim", "up", CELL, "--state-file", str(state)), env=env, stdout=out,
                                       stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists() or "is up" not in log.read_text():
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        journal = tmp_path / "run.jsonl"
        run = subprocess.run(command("run", TASK, "--cell", CELL, "--json", "--journal", str(journal)), env=env,
                             capture_output=True, text=True, timeout=10 * WAIT)
        plain = subprocess.run(command("run", TASK, "--cell", CELL, "--json"),
                               env={**env, "PNP_OPCUA_PKI": "", "PNP_OPCUA_SECURITY": "None"},
                               capture_output=True, text=True, timeout=10 * WAIT)
        assert stop(up, signal.SIGINT) == 0, log.read_text()
    assert sorted(p.name for p in (pki / "trusted").iterdir()) == ["binpicking-pc-ua.der", "screwdriver-ua.der"]
    assert run.returncode == 0, run.stdout + run.stderr
    assert json.loads(run.stdout)["outcome"] == "succeeded"
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    assert [r["event"] for r in records if r["kind"] == "event" and r["device"] == "screwdriver-ua"] == \
        ["Completed", "Completed"]
    assert plain.returncode != 0
    assert "the device offers no endpoint with security mode None" in plain.stdout + plain.stderr, \
        plain.stdout + plain.stderr
