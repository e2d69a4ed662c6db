"""Issue 29: a new user writes a library with a new skill from docs/formats.md alone, and runs it.

The library under ``tests/data/libraries/glue-dispensing`` is the one the docs show, file by file;
these tests keep the two equal and take the library through every command a user runs on it.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parent.parent.parent
LIBRARY = Path(__file__).parent.parent / "data" / "libraries" / "glue-dispensing"
CELL = LIBRARY / "cells" / "glue-cell.yaml"
TASK = LIBRARY / "tasks" / "glue.yaml"


def pnp(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          timeout=600, cwd=cwd)


def _own_terms_section() -> str:
    text = (ROOT / "docs" / "formats.md").read_text(encoding="utf-8")
    start = text.index("\n## Your own terms\n")
    return text[start:text.index("\n## ", start + 1)]


def test_the_docs_name_the_root_of_each_kind_of_term_and_the_forms_a_user_needs() -> None:
    section = _own_terms_section()
    for root in ("pnp:Device", "pnp:Skill", "pnp:StateConcept", "pnp:Quantity", "pnp:mandatoryState"):
        assert f"`{root}`" in section, root
    assert '"xirp://HOST:PORT"' in section and '"upnp://HOST:PORT"' in section
    assert 'pnp:unit ""' in section


def test_the_docs_show_every_file_of_the_library_as_it_is() -> None:
    blocks = re.findall(r"```(?:turtle|xml|yaml)\n(.*?)```", _own_terms_section(), re.S)
    files = sorted(p for p in LIBRARY.rglob("*") if p.is_file())
    assert sorted(b.splitlines()[0] for b in blocks) == sorted(
        ("<!-- {} -->" if f.suffix == ".scxml" else "# {}").format(f.relative_to(LIBRARY).as_posix()) for f in files)
    for f in files:
        assert f.read_text(encoding="utf-8") in blocks, f


def test_the_library_with_a_new_skill_validates_and_is_offered() -> None:
    result = pnp("validate", str(LIBRARY.relative_to(ROOT)))
    assert (result.returncode, result.stdout) == (0, "7 files valid\n"), result.stdout + result.stderr
    vocab = json.loads(pnp("--library", str(LIBRARY), "vocab", "--json").stdout)
    skill = next(s for s in vocab["skills"] if s["iri"] == "http://example.org/glue#CanDispense")
    assert len(skill["mandatory_states"]) == 2
    offered = json.loads(pnp("capabilities", "--cell", str(CELL), "--json").stdout)
    command = next(c for c in offered["offered"] if c["command"] == "lay-bead")
    assert command["bindings"] == [{"dispenser": "dispenser"}]


def test_a_chart_without_a_mandatory_state_of_the_new_skill_is_named(tmp_path: Path) -> None:
    library = tmp_path / "glue-dispensing"
    subprocess.run(["cp", "-r", str(LIBRARY), str(library)], check=True)
    chart = library / "devices" / "dispenser.scxml"
    chart.write_text(chart.read_text(encoding="utf-8").replace('glue#BeadLaid"', 'glue#Dispensing"'),
                     encoding="utf-8")
    result = pnp("validate", "glue-dispensing", cwd=tmp_path)
    assert result.returncode == 1
    assert ("glue-dispensing/devices/dispenser.ttl:8: device dispenser has skill CanDispense but its Device State "
            "Chart lacks the mandatory state 'BeadLaid'") in result.stdout


def test_the_library_task_checks_generates_and_runs_on_its_simulated_device(tmp_path: Path) -> None:
    checked = pnp("check", str(TASK), "--cell", str(CELL))
    assert checked.returncode == 0, checked.stderr
    assert checked.stdout.splitlines()[0] == "task glue in cell glue-cell: plausible"
    assert checked.stdout.splitlines()[1].startswith("estimated cycle time: ")
    generated = pnp("generate", str(TASK), "--cell", str(CELL), "-o", str(tmp_path / "out"))
    assert generated.returncode == 0, generated.stdout + generated.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "glue.closed-world.scxml", "glue.task.scxml", "step01-lay-bead.scxml"]
    journal = tmp_path / "run.jsonl"
    run = pnp("run", str(TASK), "--cell", str(CELL), "--sim", "--journal", str(journal))
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr
    assert "→ dispenser: Dispense {'GlueKind': 'polyurethane', 'BeadLength': 120.0}" in run.stdout
    records = [json.loads(line) for line in journal.read_text(encoding="utf-8").splitlines()]
    assert [r["state"] for r in records if r["kind"] == "state" and r.get("device") == "dispenser"][-1] == "laid"
