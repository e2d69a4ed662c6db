"""A library's devices and processes generated and run in simulation, as a user runs them."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from lxml import etree

from plugnproduce import service
from plugnproduce.ontology.vocabulary import PNP_IRI, concept_iri
from tests.knowledge.test_libraries import TF, THREE_FINGER, bin_picking_cell

BUILTIN = service.builtin()
GRIPPER_3F = THREE_FINGER / "devices" / "gripper-3f.ttl"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=120)


def test_the_bin_picking_task_runs_with_a_user_gripper(tmp_path: Path) -> None:
    cell = bin_picking_cell(tmp_path, [THREE_FINGER], GRIPPER_3F)
    task = tmp_path / "task.yaml"
    task.write_text((BUILTIN / "tasks" / "bin-picking.yaml").read_text().replace("gripper: gripper}",
                                                                                "gripper: gripper-3f}"))
    result = pnp("run", str(task), "--cell", str(cell), "--sim", "--journal", str(tmp_path / "run.jsonl"))
    assert result.returncode == 0, result.stderr
    assert "end: succeeded" in result.stdout and "gripper-3f: Close" in result.stdout


def test_a_one_state_role_region_completes_and_a_fractional_default_is_sent(tmp_path: Path) -> None:
    cell = bin_picking_cell(tmp_path, [THREE_FINGER])  # the built-in gripper: its chart sits beside its Turtle
    result = pnp("run", str(THREE_FINGER / "tasks" / "squeeze-and-open.yaml"), "--cell", str(cell), "--sim",
                 "--journal", str(tmp_path / "run.jsonl"))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "end: succeeded" in result.stdout


def test_generated_charts_carry_plain_numbers_and_foreign_concept_iris(tmp_path: Path) -> None:
    cell = bin_picking_cell(tmp_path, [THREE_FINGER], GRIPPER_3F)
    out = tmp_path / "out"
    result = pnp("generate", str(THREE_FINGER / "tasks" / "squeeze-and-open.yaml"), "--cell", str(cell),
                 "-o", str(out), "--per-device")
    assert result.returncode == 0, result.stderr
    texts = "".join(p.read_text() for p in sorted(out.glob("*.scxml")))
    assert 'expr="40.5"' in texts and "Decimal" not in texts
    concepts = {concept_iri(v) for p in out.glob("*.scxml")
                for v in etree.parse(str(p)).xpath("//@pnp:concept", namespaces={"pnp": PNP_IRI})}
    assert TF + "ClosedAroundPart" in concepts
    assert PNP_IRI + "ClosedAroundPart" not in concepts
    assert re.search(r"pnp:concept=\"http://example.org/three-finger#ClosedAroundPart\"", texts)
