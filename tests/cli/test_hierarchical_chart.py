"""A hierarchical Device State Chart end to end: the PackML-style screwdriver of a library written outside the
package (tests/data/libraries/packml-screwing) is validated, checked, verified, generated, run and drawn."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from plugnproduce.statechart import schema_problems

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "packml-screwing"
CELL = LIBRARY / "cells" / "packml-screwing.yaml"
TASK = LIBRARY / "tasks" / "screw-twice.yaml"
CHART = LIBRARY / "devices" / "packml-screwdriver.scxml"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=180)


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    """A copy of the library to edit."""
    return Path(shutil.copytree(LIBRARY, tmp_path / "packml-screwing"))


def test_the_library_validates_with_its_mandatory_states_inside_compound_states() -> None:
    result = pnp("validate", str(LIBRARY))
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stdout.strip() == "5 files valid"


def test_a_mandatory_state_missing_from_inside_the_compound_states_is_a_finding(library: Path) -> None:
    chart = library / "devices" / "packml-screwdriver.scxml"
    chart.write_text(chart.read_text().replace('id="Complete" pnp:concept="Fastened"', 'id="Complete"'))
    result = pnp("validate", str(library))
    assert result.returncode == 1
    assert ("device packml-screwdriver has skill CanScrew but its Device State Chart lacks the mandatory state "
            "'Fastened'") in result.stdout


def test_a_mandatory_concept_on_a_compound_state_holds_for_the_states_inside_it(library: Path) -> None:
    """Fastened moved from the Complete state onto a compound state around it: still there, still planned to."""
    chart = library / "devices" / "packml-screwdriver.scxml"
    text = chart.read_text().replace('<state id="Complete" pnp:concept="Fastened">',
                                     '<state id="Done" pnp:concept="Fastened"><state id="Complete">')
    chart.write_text(text.replace('<transition event="xirp.request.Reset" target="Idle"/>\n      </state>',
                                  '<transition event="xirp.request.Reset" target="Idle"/>\n      </state></state>', 1))
    assert pnp("validate", str(library)).returncode == 0
    checked = pnp("check", str(library / "tasks" / "screw-twice.yaml"), "--cell",
                  str(library / "cells" / "packml-screwing.yaml"))
    assert checked.returncode == 0 and "plausible" in checked.stdout, checked.stdout + checked.stderr


def test_check_and_verify_the_task_on_the_hierarchical_chart() -> None:
    checked = pnp("check", str(TASK), "--cell", str(CELL))
    assert checked.returncode == 0, checked.stderr
    assert checked.stdout.strip().splitlines() == ["task screw-twice in cell packml-screwing: plausible",
                                                   "estimated cycle time: 1.60 s"]  # two screws, 0.8 s each
    verified = pnp("verify", str(TASK), "--cell", str(CELL), "--json")
    assert verified.returncode == 0, verified.stderr
    assert json.loads(verified.stdout)["verdict"] == "proved"


def test_generate_writes_w3c_valid_scxml_that_resets_the_skill_before_it_starts_again(tmp_path: Path) -> None:
    out = tmp_path / "gen"
    result = pnp("generate", str(TASK), "--cell", str(CELL), "-o", str(out), "--per-device")
    assert result.returncode == 0, result.stderr
    for chart in sorted(out.glob("*.scxml")):
        assert schema_problems(chart.read_bytes(), chart) == [], chart.name
    step2 = (out / "step02-screw.scxml").read_text()
    assert step2.index('event="xirp.request.Reset"') < step2.index('event="xirp.request.Start"')
    assert 'pnp:deviceState="Execute"' in step2  # the path goes through the states inside Running


def test_run_on_the_simulated_cell(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--cell", str(CELL), "--sim", "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    sent = [r["command"] for r in records if r["kind"] == "command" and r.get("device") == "packml-screwdriver"]
    assert sent == ["Start", "Reset", "Start"]
    assert records[-1]["device_states"] == {"cobot": "at_pose", "packml-screwdriver": "Complete"}


def test_a_fault_while_the_skill_executes_aborts_it_through_its_superstate(library: Path, tmp_path: Path) -> None:
    """The skill stays in Execute (three levels deep) until the controller gives up waiting; the safe stop is the
    Abort written once on the outermost superstate, and the device takes it from there."""
    chart = library / "devices" / "packml-screwdriver.scxml"
    chart.write_text(chart.read_text().replace('event="skill.executed" delay="300ms"',
                                               'event="skill.executed" delay="600s"'))
    ttl = library / "devices" / "packml-screwdriver.ttl"
    ttl.write_text(ttl.read_text().replace("pnp:commandTimeout 4.0", "pnp:commandTimeout 1.0"))
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(library / "tasks" / "screw-twice.yaml"), "--cell",
                 str(library / "cells" / "packml-screwing.yaml"), "--sim", "--journal", str(journal))
    assert result.returncode == 1, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    (stop,) = [r for r in records if r["kind"] == "stop" and r["device"] == "packml-screwdriver"]
    assert stop["request"] == "Abort" and stop["answer"] == "accepted"
    assert stop["state"] in ("Aborting", "Aborted")


def test_draw_shows_the_compound_states_as_clusters(tmp_path: Path) -> None:
    out = tmp_path / "packml.svg"
    assert pnp("draw", str(CHART), "-o", str(out)).returncode == 0
    svg = out.read_text()
    for name in ("Abortable", "Operating", "Running"):
        assert f"<title>cluster_{name}</title>" in svg
    running = svg[svg.index("<title>cluster_Running</title>"):]
    assert "Running «Screwing»" in running[: running.index("</g>")]


def test_the_same_skill_over_upnp_runs_on_the_simulated_cell(library: Path, tmp_path: Path) -> None:
    """The hierarchical chart behind UPnP: its actions are the requests of every state, nested ones included."""
    chart = library / "devices" / "packml-screwdriver.scxml"
    chart.write_text(chart.read_text().replace("xirp.", "upnp.").replace('type="xirp"', 'type="upnp"'))
    ttl = library / "devices" / "packml-screwdriver.ttl"
    ttl.write_text(ttl.read_text().replace("pnp:XIRP", "pnp:UPnP").replace("xirp://", "upnp://"))
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(library / "tasks" / "screw-twice.yaml"), "--cell",
                 str(library / "cells" / "packml-screwing.yaml"), "--sim", "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    assert [r["command"] for r in records if r["kind"] == "command" and r["device"] == "packml-screwdriver"] == [
        "Start", "Reset", "Start"]
    assert records[-1]["device_states"]["packml-screwdriver"] == "Complete"
    assert records[0]["devices"]["packml-screwdriver"].startswith("http://127.0.0.1:")  # its UPnP description
