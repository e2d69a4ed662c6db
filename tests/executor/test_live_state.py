"""Planning from the live state: on a cell started by ``pnp sim up``, each run starts where the last left the devices."""

from __future__ import annotations

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
from tests.lines import WAIT
from tests.processes import started, stop

CELL = str(service.builtin("cells", "bin-picking.yaml"))
PICK_AND_PLACE = str(service.builtin("tasks", "pick-and-place.yaml"))


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return {**os.environ, "PNP_SSDP_PORT": str(private_network().port), "PNP_RUNS": str(tmp_path / "runs")}


@pytest.fixture
def simulated_cell(env: dict[str, str], tmp_path: Path) -> Iterator[Path]:
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    with log.open("w") as out, started([sys.executable, "-m", "plugnproduce", "sim", "up", CELL, "--state-file",
                                        str(state)], env=env, stdout=out, stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists():  # polling a file the process writes once its devices are announced
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        yield tmp_path / "runs"
        assert stop(up, signal.SIGINT) == 0, log.read_text()  # Ctrl-C; a fully loaded machine stops it late


def pnp(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    """``pnp ARGS``, waiting up to 60 s for the devices: a fully loaded machine answers discovery late."""
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args, "--discovery-timeout", "60"],
                          capture_output=True, text=True, timeout=180, env=env)


def test_a_cell_whose_devices_do_not_answer_is_bad_input_after_the_discovery_timeout(
        env: dict[str, str], tmp_path: Path) -> None:
    """Nothing runs on this private network: the run names the missing devices and the wait it gave them."""
    done = subprocess.run([sys.executable, "-m", "plugnproduce", "run", PICK_AND_PLACE, "--cell", CELL,
                           "--discovery-timeout", "0.5"], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "error: device(s) robot, gripper, sensor3d, binpicking-pc of the cell not found on the network within 0.5 s"]
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").iterdir()), "no journal: nothing ran"


def task(folder: Path, name: str, *commands: str) -> str:
    path = folder / f"{name}.yaml"
    path.write_text(f"task: {name}\nsteps:\n" + "".join(f"  - command: {c}\n" for c in commands))
    return str(path)


def test_a_task_after_one_that_closed_the_gripper_is_refused_and_repaired_from_the_reported_state(
        simulated_cell: Path, env: dict[str, str], tmp_path: Path) -> None:
    close = pnp(env, "run", task(tmp_path, "close", "close-gripper"), "--cell", CELL)
    assert close.returncode == 0, close.stdout + close.stderr
    runs_before = sorted(simulated_cell.iterdir())

    refused = pnp(env, "run", PICK_AND_PLACE, "--cell", CELL)
    assert refused.returncode == 1
    problem = next(line for line in refused.stderr.splitlines() if ": step 1 (pick-and-place)" in line)
    assert "device 'gripper'" in problem and "state 'closed'" in problem and "(the state it reports)" in problem
    assert sorted(simulated_cell.iterdir()) == runs_before, "no journal: no command went out"

    repair = pnp(env, "repair", PICK_AND_PLACE, "--cell", CELL, "--live")
    assert repair.returncode == 0, repair.stderr
    first = repair.stdout.split("repair 1", 1)[1].splitlines()[1]
    assert first.strip().startswith("- insert open-gripper before step 1 (pick-and-place)")
    assert pnp(env, "check", PICK_AND_PLACE, "--cell", CELL).returncode == 0, "offline, from the charts: plausible"

    opened = pnp(env, "run", task(tmp_path, "open", "open-gripper"), "--cell", CELL)
    assert opened.returncode == 0, opened.stdout + opened.stderr
    again = pnp(env, "run", PICK_AND_PLACE, "--cell", CELL)
    assert again.returncode == 0, again.stdout + again.stderr


def test_assume_initial_plans_from_the_charts_and_the_device_refuses(
        simulated_cell: Path, env: dict[str, str], tmp_path: Path) -> None:
    assert pnp(env, "run", task(tmp_path, "close", "close-gripper"), "--cell", CELL).returncode == 0
    blind = pnp(env, "run", PICK_AND_PLACE, "--cell", CELL, "--assume-initial", "--json")
    assert blind.returncode == 1
    assert "refused" in blind.stdout and "gripper" in blind.stdout
