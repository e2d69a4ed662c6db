"""A library written from the documentation alone (a machine-tending cell), with ``PNP_LIBRARY`` set."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from plugnproduce import service

LIBRARIES = Path(__file__).parents[1] / "data" / "libraries"
MT = LIBRARIES / "machine-tending"
CELL = MT / "cells" / "machine-tending.yaml"
ADAPTIVE = LIBRARIES / "adaptive-gripper"
LIBRARY_PROCESSES = {"open-door", "close-door", "machine", "load-machine", "unload-machine"}


def pnp(*args: str, library: Path = MT) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PNP_LIBRARY": str(library)}
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          timeout=120, env=env)


@pytest.fixture(scope="module")
def knowledge() -> service.Knowledge:
    return service.knowledge((MT,))


def test_the_library_processes_are_offered(knowledge: service.Knowledge) -> None:
    offered = set(service.capabilities(CELL, knowledge).commands())
    assert LIBRARY_PROCESSES <= offered


def test_the_library_validates() -> None:
    result = pnp("validate", str(MT))
    assert result.returncode == 0, result.stdout


def test_the_valid_task_runs_to_the_end_in_simulation(tmp_path: Path) -> None:
    result = pnp("run", str(MT / "tasks" / "machine-tending.yaml"), "--cell", str(CELL), "--sim",
                 "--journal", str(tmp_path / "run.jsonl"))
    assert result.returncode == 0, result.stdout + result.stderr
    report = pnp("report", str(tmp_path / "run.jsonl"))
    assert "end: succeeded" in report.stdout


def test_a_fault_stops_the_library_robot_with_the_library_s_own_stop_request(tmp_path: Path) -> None:
    """The library's robot declares its stop with its own concept, below pnp:SafeStop."""
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(MT / "tasks" / "machine-tending.yaml"), "--cell", str(CELL), "--sim",
                 "--faults", "mt-robot:error-response:MoveTo", "--journal", str(journal))
    assert result.returncode == 1, result.stdout + result.stderr
    stops = {r["device"]: r for r in service.report(journal).of_kind("stop")}
    assert (stops["mt-robot"]["request"], stops["mt-robot"]["answer"]) == ("ProtectiveStop", "accepted")
    assert pnp("report", str(journal)).stdout.rstrip().endswith("stopped safely")


def test_machining_with_the_door_open_is_refused_at_its_step_naming_the_door_state() -> None:
    result = pnp("check", str(MT / "tasks" / "machining-door-open.yaml"), "--cell", str(CELL))
    assert result.returncode == 1
    problem = next(line for line in result.stdout.splitlines() if ": step " in line)
    assert "step 3 (machine)" in problem and "'mt-cnc'" in problem and "door open" in problem


def test_repair_inserts_the_door_step_first(knowledge: service.Knowledge) -> None:
    repairs = service.repair(MT / "tasks" / "machining-door-open.yaml", CELL, knowledge=knowledge)
    assert [e.text for e in repairs[0].edits] == ["insert close-door before step 3 (machine)"]


def test_a_user_gripper_subclass_in_the_bin_picking_cell_runs_the_bin_picking_task(tmp_path: Path) -> None:
    cell = ADAPTIVE / "cells" / "bin-picking-adaptive.yaml"
    assert "pick" in service.capabilities(cell).commands()
    task = tmp_path / "bin-picking.yaml"  # the built-in task, its explicit bindings left to the reasoner
    lines = (service.builtin("tasks", "bin-picking.yaml")).read_text().splitlines()
    task.write_text("\n".join(line for line in lines if "bind:" not in line) + "\n")
    result = pnp("run", str(task), "--cell", str(cell), "--sim", "--journal", str(tmp_path / "run.jsonl"),
                 library=ADAPTIVE)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "adaptive-gripper: Close" in result.stdout


def test_a_library_skill_s_mandatory_state_is_enforced(tmp_path: Path) -> None:
    import shutil

    shutil.copytree(MT, tmp_path / "mt")
    chart = tmp_path / "mt" / "devices" / "mt-cnc.scxml"
    text = chart.read_text()
    for kind in ("Open", "Closed"):
        text = text.replace(f'"http://example.org/machine-tending#Door{kind}WithRawPart"', f'"Door{kind}"')
    chart.write_text(text)
    result = pnp("validate", str(tmp_path / "mt"))
    assert result.returncode == 1
    assert ("lacks the mandatory state 'RawPartLoaded'; expected a state annotated "
            "http://example.org/machine-tending#RawPartLoaded") in result.stdout


def test_one_file_of_a_library_validates_with_the_library_s_ontology() -> None:
    result = pnp("validate", str(MT / "devices" / "mt-cnc.ttl"), library=Path("/nonexistent-is-not-used"))
    assert result.returncode == 2  # a missing library folder is bad input...
    env = {k: v for k, v in os.environ.items() if k != "PNP_LIBRARY"}
    alone = subprocess.run([sys.executable, "-m", "plugnproduce", "validate", str(MT / "devices" / "mt-cnc.ttl")],
                           capture_output=True, text=True, timeout=120, env=env)
    assert alone.returncode == 0, alone.stdout  # ...but none is needed: the file's own library is found
