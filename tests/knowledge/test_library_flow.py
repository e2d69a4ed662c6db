"""A library's own process gives back outputs and outcomes: a library task links and loops on them."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

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


MOST_SPECIFIC = LIBRARY / "tasks" / "empty-or-not-found.yaml"
HOME = [0.3, 0, 0.4, 0, 180, 0]
"""The BinEmpty branch's pose (the NoPartFound branch's is the viewing pose [0.4, 0.1, 0.45, 0, 180, 0])."""


@pytest.mark.parametrize(("parts", "outcome", "branch", "steps"), [
    (0, "BinEmpty", "BinEmpty", [(1, "find-part"), (3, "move-to")]),
    (1, "PartFound", "PartFound", [(1, "find-part"), (4, "pick"), (5, "place")]),
])
def test_an_outcome_takes_the_branch_of_the_most_specific_outcome_it_falls_under_not_the_first_written(
        tmp_path: Path, parts: int, outcome: str, branch: str, steps: list[tuple[int, str]]) -> None:
    """BinEmpty falls under NoPartFound, whose branch is written first (the library's PartOccluded takes it):
    the empty bin takes the BinEmpty branch and the robot goes home, not to the viewing pose."""
    assert pnp("check", str(MOST_SPECIFIC), "--cell", str(CELL)).returncode == 0
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(MOST_SPECIFIC), "--sim", "--bin-parts", str(parts), "--bin-seed", "5",
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    records = [json.loads(line) for line in journal.read_text(encoding="utf-8").splitlines()]
    assert [(r["outcome"], r["branch"]) for r in records if r["kind"] == "branch"] == [(outcome, branch)]
    assert [(r["step"], r["command"]) for r in records if r["kind"] == "step"] == steps
    moves = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r["command"] == "MoveTo"]
    if outcome == "BinEmpty":
        assert moves == [HOME]
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "succeeded"
