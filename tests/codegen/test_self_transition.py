"""A role's region that goes from a state to another state of the same concept (Open → Open) with parameters.

The timed-cell library's ``approach-and-open`` hands the gripper its ``opening_angle`` on the way from Open to
Open: the device's own chart takes that request (``SetAngle``, open → configuring → open), so the step must
send it. Code generation, the plausibility check, the cycle-time estimate and verification walk the same path.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

from lxml import etree

TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
TASK, CELL = TIMED / "tasks" / "approach-while-opening.yaml", TIMED / "cells" / "timed-cell.yaml"
SCXML = "{http://www.w3.org/2005/07/scxml}"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", "--library", str(TIMED), *args],
                          capture_output=True, text=True, timeout=300)


def test_issue_27_the_opening_angle_of_an_open_to_open_region_reaches_the_gripper(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--cell", str(CELL), "--sim", "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text(encoding="utf-8").splitlines()]
    sent = [(r["step"], r["command"], r["params"]) for r in records
            if r["kind"] == "command" and r["device"] == "tc-gripper"]
    assert sent == [(2, "SetAngle", {"OpeningAngle": 40}), (3, "SetAngle", {"OpeningAngle": 30})]


def test_issue_27_the_generated_step_sends_the_angle_and_waits_for_the_gripper(tmp_path: Path) -> None:
    result = pnp("generate", str(TASK), "--cell", str(CELL), "-o", str(tmp_path))
    assert result.returncode == 0, result.stdout + result.stderr
    chart = etree.parse(str(tmp_path / "step02-approach-and-open.scxml"))
    sends = [(s.get("event"), [(p.get("name"), p.get("expr")) for p in s.iter(f"{SCXML}param")])
             for s in chart.iter(f"{SCXML}send") if s.get("target") == "tc-gripper"]
    assert len(sends) == 1 and sends[0][0] == "xirp.request.SetAngle"
    assert [name for name, _ in sends[0][1]] == ["OpeningAngle"]
    waits = {t.get("event") for t in chart.iter(f"{SCXML}transition")}
    assert "tc-gripper.xirp.event.angle_set" in waits


def test_issue_27_check_estimate_and_verify_walk_the_same_open_to_open_path() -> None:
    check = pnp("check", str(TASK), "--cell", str(CELL), "--json")
    assert check.returncode == 0, check.stdout + check.stderr
    steps = json.loads(check.stdout)["cycle_time"]["steps"]
    assert [s["seconds"] for s in steps][2] == 0.5  # the gripper's declared SetAngle time, longer than the move
    verify = pnp("verify", str(TASK), "--cell", str(CELL), "--json")
    assert verify.returncode == 0, verify.stdout + verify.stderr
    answer = json.loads(verify.stdout)
    assert answer["verdict"] == "proved"
    assert answer["states"] > 10  # the gripper's configuring is explored, not skipped (10 states without it)


def test_issue_27_an_angle_the_gripper_takes_only_when_closed_is_a_finding_of_check_verify_and_generate(
        tmp_path: Path) -> None:
    """The same library with a gripper that takes SetAngle only in closed: reaching it would close the gripper
    where the step says it stays open, so no route takes the angle, and the three commands say it would be lost."""
    library = tmp_path / "timed-cell"
    shutil.copytree(TIMED, library)
    chart = library / "devices" / "tc-gripper.scxml"
    text = chart.read_text(encoding="utf-8")
    set_angle = '    <transition event="xirp.request.SetAngle" target="configuring" pnp:accepts="OpeningAngle"/>\n'
    opens = '    <transition event="xirp.request.Open" target="opening"/>\n'
    chart.write_text(text.replace(set_angle, "").replace(opens, opens + set_angle), encoding="utf-8")
    task, cell = library / "tasks" / TASK.name, library / "cells" / CELL.name
    lost = [f"{task}:{line}: step {step} (approach-and-open): parameter opening_angle (opening angle) goes to device "
            "'tc-gripper' (role 'gripper'), but the route its chart takes from state 'open' passes no command that "
            "accepts opening angle; the value would be lost" for line, step in ((7, 2), (9, 3))]
    for command in (["check"], ["verify"], ["generate", "-o", str(tmp_path / "out")]):
        result = subprocess.run([sys.executable, "-m", "plugnproduce", "--library", str(library), command[0],
                                 str(task), "--cell", str(cell), *command[1:]], capture_output=True, text=True,
                                timeout=300)
        assert result.returncode == 1, (command, result.stdout, result.stderr)
        assert [line for line in (result.stdout + result.stderr).splitlines() if "opening_angle" in line] == lost
    assert not (tmp_path / "out").exists()
