"""``pnp vocab``: the terms a description may use, from the loaded knowledge."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from plugnproduce.cli import app
from tests.knowledge.test_libraries import TF, THREE_FINGER

runner = CliRunner()


def test_vocab_lists_classes_with_the_skills_they_imply() -> None:
    result = runner.invoke(app, ["vocab"])
    assert result.exit_code == 0
    line = next(x for x in result.stdout.splitlines() if x.strip().startswith("pnp:ParallelGripper "))
    assert "pnp:CanGrip" in line and "pnp:CanRelease" in line


def test_vocab_json_has_every_kind_of_term() -> None:
    doc = json.loads(runner.invoke(app, ["vocab", "--json"]).stdout)
    skills = {s["name"]: s for s in doc["skills"]}
    assert skills["pnp:CanGrip"]["mandatory_states"] == ["pnp:Closed", "pnp:Open"]
    assert "pnp:Closed" in {c["name"] for c in doc["state_concepts"]}
    grip_force = next(q for q in doc["quantities"] if q["name"] == "pnp:GripForce")
    assert {"datatype": "http://www.w3.org/2001/XMLSchema#decimal", "unit": "N"} in grip_force["used_as"]
    pick = next(p for p in doc["processes"] if p["command"] == "pick")
    gripper = next(r for r in pick["roles"] if r["role"] == "gripper")
    assert gripper == {"role": "gripper", "skill": "pnp:CanGrip", "start": "pnp:Open", "end": "pnp:Closed"}


def test_vocab_includes_a_library_s_terms() -> None:
    doc = json.loads(runner.invoke(app, ["--library", str(THREE_FINGER), "vocab", "--json"]).stdout)
    classes = {c["iri"]: c for c in doc["device_classes"]}
    assert TF + "CanAdaptiveGrip" in classes[TF + "ThreeFingerGripper"]["skills"]
    assert "squeeze" in [p["command"] for p in doc["processes"]]
