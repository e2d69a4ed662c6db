"""Resume after a fault: the devices' states are read, the rest is re-planned from them, and the run goes on.

A gripper fault in the middle of the until-empty task on a simulated, seeded bin; the resumed run empties it.
"""

from __future__ import annotations

import asyncio
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import controller, service
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.bin import SimulatedBin
from plugnproduce.sim.cell import SimulatedCell, parse_faults
from tests.lines import WAIT
from tests.processes import started, stop

CELL = service.builtin("cells", "bin-picking.yaml")
UNTIL_EMPTY = service.builtin("tasks", "bin-picking-until-empty.yaml")
LIBRARIES = Path(__file__).parent.parent / "data" / "libraries"
GRIPPER_FAULT = "gripper:error-response:Close"  # the first grip is refused: the run stops in step 2, bin full


def journal_of(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def test_resume_after_a_gripper_fault_empties_the_bin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """In process, through the controller call both faces use: the bin itself is asserted empty."""
    network = private_network()
    monkeypatch.setenv("PNP_SSDP_PORT", str(network.port))
    monkeypatch.setenv("PNP_RUNS", str(tmp_path / "runs"))
    the_cell = service.cell(CELL)
    parts = SimulatedBin(4, seed=5)
    shown: list[service.Replan] = []

    def confirm(plan: service.Replan) -> str:
        shown.append(plan)
        return "the test"

    async def scenario() -> tuple[Any, controller.Resumed]:
        async with SimulatedCell(the_cell, network=network, faults=parse_faults(GRIPPER_FAULT, the_cell.devices),
                                 bin=parts):
            first = await controller.run_task(UNTIL_EMPTY, CELL, journal=tmp_path / "first.jsonl",
                                              discovery_timeout=WAIT)
            assert first.outcome == "failed" and len(parts.parts) == 4  # stopped before any part was taken
            return first, await controller.resume_run(tmp_path / "first.jsonl", None, confirm,
                                                      journal=tmp_path / "resumed.jsonl", discovery_timeout=WAIT)

    first, resumed = asyncio.run(scenario())
    assert first.fault is not None and first.fault.device == "gripper" and first.fault.step == 2
    assert resumed.report is not None and resumed.report.outcome == "succeeded"
    assert parts.parts == [] and len(parts.taken) == 4  # the bin ends empty
    plan = shown[0]
    assert plan.states["robot"] == "at_pose" and plan.states["gripper"] == "open"  # where the safe stop left them
    assert plan.plan == "the rest of task bin-picking-until-empty from step 1"
    records = journal_of(tmp_path / "resumed.jsonl")
    assert [r["kind"] for r in records[:4]] == ["start", "stopped", "replan", "continue"]
    assert records[1]["run"] == "first" and records[1]["step"] == 2 and "fault injected" in records[1]["reason"]
    assert records[2]["states"] == plan.states and records[3]["confirmed_by"] == "the test"
    found = [r["params"]["outcome"] for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert found == ["PartFound"] * 4 + ["BinEmpty"]


def test_a_declined_plan_sends_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    network = private_network()
    monkeypatch.setenv("PNP_SSDP_PORT", str(network.port))
    the_cell = service.cell(CELL)
    parts = SimulatedBin(2, seed=1)

    async def scenario() -> controller.Resumed:
        async with SimulatedCell(the_cell, network=network, faults=parse_faults(GRIPPER_FAULT, the_cell.devices),
                                 bin=parts):
            await controller.run_task(UNTIL_EMPTY, CELL, journal=tmp_path / "first.jsonl", discovery_timeout=WAIT)
            return await controller.resume_run(tmp_path / "first.jsonl", None, lambda _: None,
                                               journal=tmp_path / "resumed.jsonl", discovery_timeout=WAIT)

    resumed = asyncio.run(scenario())
    assert resumed.report is None and not (tmp_path / "resumed.jsonl").exists()
    assert len(parts.parts) == 2


@pytest.mark.parametrize(("stopped_at", "starts", "commands"), [
    (5, 4, ["localize-part", "pick", "place"]),  # the pick takes the pose the localize before it reports
    (6, 6, ["place"]),
    (1, 1, ["localize-part", "pick", "place"] * 2),
])
def test_the_rest_of_a_library_task_starts_where_its_values_come_from(stopped_at: int, starts: int,
                                                                      commands: list[str]) -> None:
    task = service.task(LIBRARIES / "far-part" / "tasks" / "pick-where-localized.yaml")
    rest, start = service.rest_of_task(task, stopped_at)
    assert start == starts and [s.command for s in rest.steps] == commands
    assert rest.repeat == 1


def test_a_stopped_step_inside_a_loop_resumes_the_loop_from_its_first_step() -> None:
    rest, start = service.rest_of_task(service.task(UNTIL_EMPTY), 3)
    assert start == 1 and len(rest.loops) == 1 and rest.loops[0].until is not None


# ------------------------------------------------------------------ the command line, on `pnp sim up`


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return {**os.environ, "PNP_SSDP_PORT": str(private_network().port), "PNP_RUNS": str(tmp_path / "runs")}


@pytest.fixture
def faulty_cell(env: dict[str, str], tmp_path: Path) -> Iterator[Path]:
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    args = [sys.executable, "-m", "plugnproduce", "sim", "up", str(CELL), "--state-file", str(state),
            "--faults", GRIPPER_FAULT, "--bin-parts", "3", "--bin-seed", "2"]
    with log.open("w") as out, started(args, env=env, stdout=out, stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists():  # polling a file the process writes once its devices are announced
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        yield tmp_path / "runs"
        assert stop(up, signal.SIGINT) == 0, log.read_text()


def pnp(env: dict[str, str], *args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args, "--discovery-timeout", "60"],
                          capture_output=True, text=True, timeout=300, env=env, input=stdin)


def test_pnp_resume_shows_the_plan_asks_and_continues_with_yes(env: dict[str, str], faulty_cell: Path) -> None:
    first = pnp(env, "run", str(UNTIL_EMPTY), "--cell", str(CELL))
    assert first.returncode == 1 and "fault injected" in first.stdout
    (run_file,) = faulty_cell.iterdir()
    run_id = run_file.name.removesuffix(".jsonl")
    declined = pnp(env, "resume", run_id, stdin="n\n")
    assert declined.returncode == 1, declined.stderr
    assert f"run {run_id} failed at step 2: refused" in declined.stdout
    assert "plan: the rest of task bin-picking-until-empty from step 1, 6 step(s)" in declined.stdout
    assert "not resumed: the plan was not confirmed; nothing was sent" in declined.stderr
    assert len(list(faulty_cell.iterdir())) == 1  # no run started
    done = pnp(env, "resume", run_id, "--yes")
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr
    (resumed,) = set(faulty_cell.iterdir()) - {run_file}
    records = journal_of(resumed)
    assert [r["kind"] for r in records[:4]] == ["start", "stopped", "replan", "continue"]
    assert records[3]["confirmed_by"] == "--yes"
    found = [r["params"]["outcome"] for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert found == ["PartFound"] * 3 + ["BinEmpty"]  # the seeded bin of 3 parts ends empty
    again = pnp(env, "resume", resumed.name.removesuffix(".jsonl"), "--yes")
    assert again.returncode == 2 and again.stderr.strip().endswith("succeeded: nothing to resume")


def test_pnp_resume_sim_starts_the_simulated_devices_where_the_run_left_them(tmp_path: Path) -> None:
    """A `pnp run --sim` cell ends with its run: `pnp resume --sim` simulates it again, each device in the state the
    journal's end record left it in, on a bin of the parts left (none was taken before the fault), at the speed the
    run had."""
    env = {**os.environ, "PNP_RUNS": str(tmp_path / "runs")}

    def pnp_sim(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                              timeout=600, env=env)

    first = pnp_sim("run", str(UNTIL_EMPTY), "--sim", "--faults", GRIPPER_FAULT, "--bin-parts", "3", "--bin-seed",
                    "2", "--speed", "4", "--journal", str(tmp_path / "first.jsonl"))
    assert first.returncode == 1, first.stderr
    left = journal_of(tmp_path / "first.jsonl")[-1]["device_states"]
    assert left["robot"] == "at_pose"  # not its chart's initial state (home)
    done = pnp_sim("resume", str(tmp_path / "first.jsonl"), "--sim", "--bin-parts", "3", "--bin-seed", "2", "--yes",
                   "--journal", str(tmp_path / "resumed.jsonl"))
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr
    records = journal_of(tmp_path / "resumed.jsonl")
    assert [r["kind"] for r in records[:4]] == ["start", "stopped", "replan", "continue"]
    assert records[0]["speed"] == 4
    assert records[2]["states"] == left  # the simulated devices report where the run left them
    found = [r["params"] for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert [f["outcome"] for f in found] == ["PartFound"] * 3 + ["BinEmpty"]
    assert sorted(f["part_pose"] for f in found[:-1]) == sorted(p.pose for p in SimulatedBin(3, 2).parts)
    wrong = pnp_sim("resume", str(tmp_path / "first.jsonl"), "--bin-parts", "3")
    assert wrong.returncode == 2 and "--faults and --bin-parts work on simulated devices: add --sim" in wrong.stderr


def stopped_at(task: Any, step: int) -> service.Stopped:
    return service.Stopped("r1", Path("r1.jsonl"), task, str(CELL), "failed", "refused", step)


def test_a_rest_not_plausible_from_the_devices_states_is_repaired_and_says_how() -> None:
    """The gripper was left closed: the rest of pick-and-place gets the cheapest confirmed repair, opening it."""
    task = service.task(service.builtin("tasks", "pick-and-place.yaml"))
    plan = service.replan(stopped_at(task, 1), service.cell(CELL).reported({"gripper": "closed"}))
    assert plan.plan == "the rest of task pick-and-place from step 1, repaired"
    assert plan.repairs == ("insert open-gripper before step 1 (pick-and-place)",)
    assert [s.command for s in plan.task.steps] == ["open-gripper", "pick-and-place", "move-to"]
    assert plan.states["gripper"] == "closed"


def test_resume_with_a_goal_plans_it_afresh_from_the_devices_states() -> None:
    """Holding a part (gripper closed, robot at a pose), the bin-emptying goal first places it, then loops."""
    task = service.task(UNTIL_EMPTY)
    cell = service.cell(CELL).reported({"gripper": "closed", "robot": "at_pose"})
    plan = service.replan(stopped_at(task, 2), cell, goal=service.builtin("goals", "empty-the-bin.yaml"))
    assert plan.plan == "goal empty-the-bin" and plan.repairs == ()
    assert plan.task.steps[0].command == "place" and len(plan.task.loops) == 1
    assert service.check(plan.task, cell).plausible
