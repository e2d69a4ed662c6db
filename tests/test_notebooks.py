"""The notebooks run from top to bottom and show what their text says they show; they are stored with
their outputs for reading."""

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
        r"built-in knows ThreeFingerGripper: False",
        r"ThreeFingerGripper implies: \[.*'pnp:CanGrip', 'pnp:CanRelease'\]",  # derived from the new class
        r"\d+ files, valid: True",
        r"gripper-3f\.scxml:\d+: pnp:accepts: unknown quantity GripForse .*did you mean GripForce\?",
        r"changed: True",
        r"\+ pick \['gripper=gripper-3f robot=robot'\]",
        r"plausible: True",
        r"outcome: succeeded",
        r'<owl:imports rdf:resource="http://example.org/protege-lab/skills"/>',  # owlready2 saved RDF/XML
        r"files classified: pnp\.ttl lab\.owl skills\.owx",  # the import, through the catalog
        r"valid: True",
        r"pick +\(\{'gripper': 'soft-gripper', 'robot': 'robot'\},\)",
        r"every 'soft gripper' has the skill 'can grip' .*@ \(inferred\)",
        r"\[SoftGripper ⊑ ∃hasSkill\.CanSoftGrip\]  @ lab\.owl:\d+",
        r"\[CanSoftGrip ⊑ CanGrip\]  @ skills\.owx:\d+",
        r"catalogue device vacuum-gripper roles gained: \['screw\.screwdriver'\]",
        r"new violation: vacuum-gripper\.ttl:\d+: .*lacks the mandatory state 'Fastened'",
        r"device classes in the export: +(\d+) \| in pnp vocab: \1\b",
        r"SoftGripper is a: \['Gripper', 'GrippingDevice'\]",
        r"marked: \['HermiT'\]",
        r"pnp:Open ≡ pnp:Released",
    ],
    "batch-feasibility": [
        r"256 configurations answered",
        r"plausible for every task: 1\b",
        r"binpicking-pc\+robot\+sensor3d: cheapest purchase gripper \(1800\)",
        r"binpicking-pc\+sensor3d: cheapest purchase gripper\+robot \(33800\)",
        r"\d+ cells: step 2 of bin-picking: several devices can play role gripper",
        r"coverage 2: from cost 45800",
    ],
    "cell-planner": [
        r"offered +pick +gripper=gripper robot=robot",
        r"not +screw +role 'screwdriver' of screw needs a device that can screw",
        r"implausible: 1 problem",
        r"step 2 \(bin-pick\): device 'gripper' .* the step needs it open",
        r"repair 1 \(cost \d+\): insert open-gripper before step 2",
        r"repaired task plausible: True",
    ],
    "explain-why": [
        r"pick offered: True",
        r"every 'parallel gripper' has the skill 'can grip' \| inferred by HermiT: True",
        r"ParallelGripper ⊑ ∃hasSkill\.CanParallelGrip  @ pnp\.ttl:\d+",
        r"rule: roles\.lp:\d+",
        r"no device in cell 'bin-picking' has the skill 'can transport'",
        r"counterfactual: add device 'conveyor' .*confirmed: True",
        r"offered after plugging it in: True",
        r"with an empty catalogue: no device of the catalogue",
        r"step 1 \(bin-pick\) left device 'gripper' in state 'closed'",
        r"counterfactual: if device 'gripper' were in state 'open'",
        r"repair 1 \(solver rank \d, cost 3\)",
        r"repair 3 \(solver rank 1, cost 2\): insert open-gripper before step 2 \(bin-pick\)\n +side effect \[drops_part\]",
    ],
    "planner": [
        r"planned: 3 steps, repeated until BinEmpty",
        r"pick_pose:\s+from: localize_part\s+output: part_pose",
        r"plausible: True",
        r"verified: proved",
        r"step 2 pick +\d+\.\d\d s",
        r"estimated cycle time: \d+\.\d\d s per iteration of the loop \((\d+\.\d\d) s per part\)",
        r"buy: screwdriver 1400",
        r"ours: \['close-gripper', 'place', 'move-to', 'close-gripper'\]",
        r"Fast Downward: SOLVED_OPTIMALLY \['close-gripper', 'place', 'move-to', 'close-gripper'\]",
        r"outcome: succeeded",
        r"speed: 1; seconds per part: \d+\.\d\d \d+\.\d\d \d+\.\d\d \(estimate \d+\.\d\d\)",  # 3 parts
    ],
    "operator": [
        r"→ gripper: Close \{'GripForce': 30\}",
        r"end: succeeded",
        r"refused at step 1 \(pick-and-place\), device gripper .*fault injected",
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
    assert {p.stem for p in NOTEBOOKS} >= {"ontology-engineer", "cell-planner", "operator"}


def test_every_notebook_has_expectations() -> None:
    assert {p.stem for p in NOTEBOOKS} == set(EXPECTED)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_is_stored_with_its_outputs_and_no_local_paths(path: Path) -> None:
    # Read without Jupyter (as on a code host); outputs must not tell where they were made.
    notebook = nbformat.read(path, as_version=4)
    cells = [c for c in notebook.cells if c.cell_type == "code"]
    assert all(c.outputs for c in cells), "executed and saved with outputs"
    assert all(o.output_type != "error" for c in cells for o in c.outputs)
    text = path.read_text(encoding="utf-8")
    for local in ("/tmp/", "/home/", "/root/", "/Users/"):
        assert local not in text, local
