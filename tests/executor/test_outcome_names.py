"""One outcome, however a device writes it: full IRI, prefixed name and local name take the same branch."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from plugnproduce.executor.outcomes import resolve
from plugnproduce.ontology.vocabulary import PNP_IRI

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "iri-outcomes"
CELL = LIBRARY / "cells" / "iri-outcomes.yaml"
OCCLUDED = "http://example.org/part-finding#PartOccluded"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)


def run(task: Path, cell: Path, journal: Path) -> tuple[subprocess.CompletedProcess[str], list[dict[str, Any]]]:
    result = pnp("run", str(task), "--cell", str(cell), "--sim", "--journal", str(journal))
    return result, [json.loads(line) for line in journal.read_text(encoding="utf-8").splitlines()]


def test_outcomes_reported_by_iri_take_their_branches_and_end_the_loop(tmp_path: Path) -> None:
    result, records = run(LIBRARY / "tasks" / "iri-then-home.yaml", CELL, tmp_path / "run.jsonl")
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    branches = [(r["step"], r["outcome"], r["branch"]) for r in records if r["kind"] == "branch"]
    assert branches == [(1, "PartFound", "PartFound"), (5, "PartFound", "PartFound"), (5, "BinEmpty", "NoPartFound")]
    picks = [r for r in records if r["kind"] == "command" and r["command"] == "Close"]
    assert len(picks) == 2  # a part picked for each PartFound, by full IRI and by prefixed name
    assert [r["command"] for r in records if r["kind"] == "step"][-1] == "move-to"


def test_an_until_loop_ends_on_an_outcome_reported_by_iri(tmp_path: Path) -> None:
    result, records = run(LIBRARY / "tasks" / "iri-until-empty.yaml", CELL, tmp_path / "run.jsonl")
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    localized = [r for r in records if r["kind"] == "command" and r["command"] == "Localize"]
    assert len(localized) == 3 and records[-1]["outcome"] == "succeeded"
    assert sum(r["kind"] == "command" and r["command"] == "Close" for r in records) == 2


def test_an_outcome_the_process_does_not_declare_is_a_fault(tmp_path: Path) -> None:
    library = tmp_path / "iri-outcomes"
    shutil.copytree(LIBRARY, library)
    chart = library / "devices" / "iri-localizer.scxml"
    chart.write_text(chart.read_text(encoding="utf-8").replace("'pnp:PartFound'", "'pnp:PartLost'"), encoding="utf-8")
    cell = library / "cells" / "iri-outcomes.yaml"
    cell.write_text(cell.read_text(encoding="utf-8").replace("../../../../../descriptions",
                                                             str(Path(__file__).parents[2] / "descriptions")),
                    encoding="utf-8")
    result, records = run(library / "tasks" / "iri-then-home.yaml", cell, tmp_path / "run.jsonl")
    assert result.returncode == 1
    assert ("fault: outcome at step 5 (localize-part), device iri-localizer in state localizing: iri-localizer "
            "reported outcome 'pnp:PartLost', which localize-part does not declare") in result.stdout
    assert not any(r["kind"] == "branch" and r["outcome"] == "pnp:PartLost" for r in records)


@pytest.mark.parametrize(("reported", "expected"), [
    (PNP_IRI + "PartFound", PNP_IRI + "PartFound"),
    ("pnp:PartFound", PNP_IRI + "PartFound"),
    ("PartFound", PNP_IRI + "PartFound"),
    ("pf:PartOccluded", OCCLUDED),
    ("PartOccluded", OCCLUDED),
    ("pnp:PartOccluded", None),
    ("other:PartFound", None),
    ("NoSuchOutcome", None),
    (42, None),
    ("x" * 5000, None),
])
def test_each_spelling_resolves_to_one_declared_outcome(reported: object, expected: str | None) -> None:
    declared = (PNP_IRI + "PartFound", PNP_IRI + "BinEmpty", OCCLUDED)
    prefixes = {"pnp": PNP_IRI, "pf": "http://example.org/part-finding#"}
    assert resolve(reported, declared, prefixes) == expected
