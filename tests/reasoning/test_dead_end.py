"""A dead-end start state: a device in a state its role may start from, with no way through the role's region.

The library under tests/data/libraries/transport-lock (written outside the package) has a gripper delivered
locked open for transport: its chart starts in an Open state from which no transition leads to Closed. The
check (``stuck`` in rules/chain.lp), the batch (its twin in batch/feasibility.py) and code generation must
all say no, and say it alike.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import reasoning, service
from plugnproduce.batch import Configuration
from plugnproduce.cli import app
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.task import StuckStep
from plugnproduce.description.model import Cell
from plugnproduce.service import checks

LIBRARY = Path(__file__).parent.parent / "data" / "libraries" / "transport-lock"
CELL = LIBRARY / "cells" / "bin-picking-locked.yaml"
CLOSE = LIBRARY / "tasks" / "close-gripper.yaml"
STUCK = (f"{CLOSE}:4: step 1 (close-gripper): device 'locked-gripper' (role 'gripper') starts in state 'locked', "
         "but its state chart has no path from there through the states the role's region visits")
SENSING = ("robot", "sensor3d", "binpicking-pc")


@pytest.fixture(scope="module")
def k() -> service.Knowledge:
    return service.knowledge((LIBRARY,))


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", "--library", str(LIBRARY), *args],
                          capture_output=True, text=True, timeout=600)


def test_check_says_a_device_that_cannot_leave_its_start_state_is_stuck_at_the_steps_line() -> None:
    result = pnp("check", str(CLOSE), "--cell", str(CELL))
    assert result.returncode == 1, result.stdout + result.stderr
    assert result.stdout.splitlines()[1:] == [STUCK]


def test_the_problem_names_the_device_its_state_and_the_role(k: service.Knowledge) -> None:
    (problem,) = service.check(service.task(CLOSE), service.cell(CELL, k), k).problems
    assert (problem.step, problem.kind, problem.role, problem.device, problem.state) == (
        1, "stuck", "gripper", "locked-gripper", "locked")


def test_generate_refuses_it_in_one_line_without_a_traceback(tmp_path: Path) -> None:
    result = pnp("generate", str(CLOSE), "--cell", str(CELL), "-o", str(tmp_path / "out"))
    assert result.returncode == 1
    assert "Traceback" not in result.stderr and STUCK in result.stderr.splitlines()
    assert not (tmp_path / "out").exists()


def test_code_generation_itself_refuses_a_step_with_no_path_naming_it(k: service.Knowledge) -> None:
    """Code generation does not trust the check: a binding the check would have let through is refused by name."""
    task, cell = service.task(CLOSE), service.cell(CELL, k)
    with pytest.raises(StuckStep) as refused:
        generate_task(task, cell, [{"gripper": "locked-gripper"}], {p.id: p for p in k.processes}, k.taxonomy)
    assert str(refused.value) == (
        "step 1 (close-gripper): device 'locked-gripper' (role 'gripper') starts in state 'locked', but its state "
        "chart has no path from there through the states the role's region visits (none to a state of concept "
        "Closed)")


def test_generate_says_it_in_one_line_even_when_the_check_lets_the_step_through(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Were the check ever to miss a dead end, generate still answers with the finding at its line, exit 1."""
    real = service.check

    def lenient(*args: object, **kwargs: object) -> reasoning.CheckResult:  # the check with the stuck rule gone
        return dataclasses.replace(real(*args, **kwargs), plausible=True, problems=())  # type: ignore[arg-type]

    monkeypatch.setattr(checks, "check", lenient)  # where generate looks it up
    result = CliRunner().invoke(app, ["--library", str(LIBRARY), "generate", str(CLOSE), "--cell", str(CELL), "-o",
                                      str(tmp_path / "out"), "--no-verify"])
    assert isinstance(result.exception, SystemExit | None), result.exception
    assert result.exit_code == 1
    assert result.output.splitlines() == [STUCK + " (none to a state of concept Closed); nothing written"]
    assert not (tmp_path / "out").exists()


def configurations(k: service.Knowledge) -> list[Configuration]:
    grippers = ("gripper", "locked-gripper", "vacuum-gripper")
    return [Configuration(f"{g}+{n}", (g, *SENSING[:n])) for g in grippers for n in range(1, len(SENSING) + 1)]


def test_the_batch_says_what_check_says_for_every_configuration_with_or_without_the_dead_end(
        k: service.Knowledge) -> None:
    tasks = [service.task(CLOSE), service.task(service.builtin("tasks", "pick-and-place.yaml"))]
    configs = configurations(k)
    found = list(service.batch(configs, list(k.devices), tasks, workers=1, knowledge=k))
    by_id = {d.id: d for d in k.devices}
    checked = [tuple(t.name for t in tasks if service.check(t, Cell(c.name, tuple(by_id[d] for d in c.devices)),
                                                              k).plausible) for c in configs]
    assert [r.plausible for r in found] == checked
    plausible = dict(zip((c.name for c in configs), checked, strict=True))
    assert plausible["gripper+3"] == ("close-gripper", "pick-and-place")
    assert plausible["locked-gripper+3"] == ()  # the same cell with the locked gripper can do neither


def test_the_batch_names_the_dead_end_as_the_reason_and_buys_a_gripper_that_can_close(k: service.Knowledge) -> None:
    (row,) = service.batch([Configuration("locked", ("locked-gripper", *SENSING))], list(k.devices),
                           [service.task(CLOSE)], workers=1, knowledge=k)
    assert row.plausible == ()
    assert row.purchase is not None and row.purchase.options == ()
    assert row.purchase.impossible is not None
    assert "device locked-gripper cannot play role gripper from the state it is in" in row.purchase.impossible
