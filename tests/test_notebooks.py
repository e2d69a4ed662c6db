"""The notebooks run from top to bottom and show what their text says they show."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))

EXPECTED: dict[str, list[str]] = {
    # Per notebook, patterns its printed output must match, in this order.
    "ontology-engineer": [
        r"\d+ device classes, \d+ skills",
        r"ParallelGripper +gripping device: True .*'can grip'",  # derived, not stated
        r"Screwdriver +gripping device: False",
        r"SoftGripper can: \[.*'can grip'.*'can release'.*\]",  # the new class inherits the skills
        r"soft\.ttl:\d+: device soft has skill CanGrip but its Device State Chart lacks the mandatory state 'Closed'",
        r"\d+ files, 0 problems",
    ],
}


def _printed(notebook: nbformat.NotebookNode) -> str:
    return "".join(o.get("text", "") for c in notebook.cells if c.cell_type == "code" for o in c.outputs
                   if o.output_type == "stream")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs_and_shows_its_findings(path: Path) -> None:
    notebook = nbformat.read(path, as_version=4)
    NotebookClient(notebook, timeout=300, kernel_name="python3").execute()
    errors = [o for c in notebook.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert errors == []
    printed, at = _printed(notebook), 0
    for pattern in EXPECTED[path.stem]:
        found = re.compile(pattern).search(printed, at)
        assert found, f"{path.name}: nothing printed after position {at} matches {pattern!r}:\n{printed}"
        at = found.end()


def test_each_kind_of_user_has_a_notebook() -> None:
    assert {p.stem for p in NOTEBOOKS} >= {"ontology-engineer"}


def test_every_notebook_has_expectations() -> None:
    assert {p.stem for p in NOTEBOOKS} == set(EXPECTED)
