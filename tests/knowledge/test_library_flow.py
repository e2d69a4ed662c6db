"""A library's own process gives back outputs and outcomes: a library task links and loops on them."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from plugnproduce import service
from plugnproduce.sim.bin import SimulatedBin

LIBRARY = Path(__file__).parent.parent / "data" / "libraries" / "part-finding"
TASK = LIBRARY / "tasks" / "clear-bin.yaml"
CELL = service.builtin("cells", "bin-picking.yaml")


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", "--library", str(LIBRARY), *args],
                          capture_output=True, text=True, timeout=600)


def test_a_library_task_clears_a_simulated_bin_with_the_librarys_process(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--sim", "--bin-parts", "3", "--bin-seed", "5", "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    records = [json.loads(line) for line in journal.read_text(encoding="utf-8").splitlines()]
    used = [r["used"] for r in records if r["kind"] == "value" and r["value"] == "found.part_pose" and "used" in r]
    assert sorted(used) == sorted(p.pose for p in SimulatedBin(3, 5).parts)
    outcomes = [r["produced"] for r in records if r["kind"] == "value" and r["value"] == "outcome"]
    assert outcomes == ["PartFound"] * 3 + ["BinEmpty"]


def test_a_link_to_the_librarys_output_of_the_wrong_type_is_refused(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(TASK.read_text(encoding="utf-8").replace("output: part_pose", "output: part_type"),
                    encoding="utf-8")
    result = pnp("check", str(task), "--cell", str(CELL))
    assert result.returncode == 1
    assert (f"{task}:13: loop iteration 1: step 2 (pick): parameter pick_pose takes part_type from found, "
            "a string; the parameter takes a Pose") in result.stdout


BRANCHING = LIBRARY / "tasks" / "clear-bin-or-look-again.yaml"


def test_a_library_task_branches_on_the_librarys_own_outcome_and_runs(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(BRANCHING), "--sim", "--bin-parts", "2", "--bin-seed", "5", "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    records = [json.loads(line) for line in journal.read_text(encoding="utf-8").splitlines()]
    taken = [(r["outcome"], r["branch"]) for r in records if r["kind"] == "branch"]
    assert taken == [("PartFound", "PartFound")] * 2 + [("BinEmpty", None)]
    assert [r["command"] for r in records if r["kind"] == "step"][-1] == "move-to"


def test_verify_proves_the_library_task_on_every_outcome_its_process_declares() -> None:
    result = pnp("verify", str(BRANCHING), "--cell", str(CELL), "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    assert json.loads(result.stdout)["verdict"] == "proved"


def test_a_misspelt_library_outcome_is_refused_at_its_line(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(BRANCHING.read_text(encoding="utf-8").replace("#PartOccluded", "#PartOcluded"), encoding="utf-8")
    result = pnp("check", str(task), "--cell", str(CELL))
    assert result.returncode == 1
    assert (f"{task}:19: step 1 (find-part): branch PartOcluded: PartOcluded is not an outcome of the ontology; "
            "did you mean http://example.org/part-finding#PartOccluded") in result.stdout
