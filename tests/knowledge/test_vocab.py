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


def test_vocab_lists_the_roots_a_library_s_terms_subclass() -> None:
    result = runner.invoke(app, ["vocab"])
    lines = result.stdout.splitlines()
    assert lines[0] == "roots (every term of a library subclasses one):"
    roots = [x.split()[0] for x in lines[1:6]]
    assert roots == ["pnp:Device", "pnp:Skill", "pnp:StateConcept", "pnp:Quantity", "pnp:Outcome"]
    doc = json.loads(runner.invoke(app, ["vocab", "--json"]).stdout)
    assert [r["name"] for r in doc["roots"]] == roots
    assert {"name": "pnp:BinEmpty", "parents": ["pnp:NoPartFound"]}.items() <= next(
        o for o in doc["outcomes"] if o["name"] == "pnp:BinEmpty").items()


def test_vocab_shows_equivalent_classes_as_equivalent_not_as_parents() -> None:
    lines = runner.invoke(app, ["vocab"]).stdout.splitlines()
    assert "  pnp:Open                           pnp:GripperState  (equivalent: pnp:Released)" in lines
    assert "  pnp:Released                       pnp:GripperState  (equivalent: pnp:Open)" in lines
    doc = json.loads(runner.invoke(app, ["vocab", "--json"]).stdout)
    opened = next(c for c in doc["state_concepts"] if c["name"] == "pnp:Open")
    assert (opened["parents"], opened["equivalent"]) == (["pnp:GripperState"], ["pnp:Released"])


def test_vocab_tree_indents_each_root_s_taxonomy_with_equivalents_on_one_line() -> None:
    result = runner.invoke(app, ["vocab", "--tree"])
    assert result.exit_code == 0
    lines = result.stdout.splitlines()
    tops = [x for x in lines if not x.startswith(" ")]
    assert tops == ["pnp:Device  (device classes)", "pnp:Skill  (skills)", "pnp:StateConcept  (state concepts)",
                    "pnp:Quantity  (quantities)", "pnp:Outcome  (outcomes)"]
    grip = lines.index("  pnp:GripperState")
    assert "    pnp:Open ≡ pnp:Released" in lines[grip:]
    assert not any(x.strip() == "pnp:Released" for x in lines)
    # the hierarchy HermiT derives: a magnetic gripper is a gripping device (a defined class)
    gripping = lines.index("  pnp:GrippingDevice")
    assert lines[gripping + 1] == "    pnp:MagneticGripper"
    assert lines[lines.index("pnp:Outcome  (outcomes)") + 1:][:2] == ["  pnp:NoPartFound", "    pnp:BinEmpty"]


def test_vocab_tree_includes_a_library_s_classes_under_their_parents() -> None:
    lines = runner.invoke(app, ["--library", str(THREE_FINGER), "vocab", "--tree"]).stdout.splitlines()
    gripper = lines.index("    pnp:Gripper")
    assert "      " + TF + "ThreeFingerGripper" in lines[gripper:]


def test_vocab_tree_json_nests_children_and_groups_equivalents() -> None:
    roots = json.loads(runner.invoke(app, ["vocab", "--tree", "--json"]).stdout)
    assert [r["kind"] for r in roots] == ["device_classes", "skills", "state_concepts", "quantities", "outcomes"]
    states = roots[2]["children"]
    gripper = next(n for n in states if n["names"] == ["pnp:GripperState"])
    assert {"names": ["pnp:Open", "pnp:Released"], "children": []} in gripper["children"]
