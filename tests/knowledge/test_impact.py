"""``pnp impact``: what a TBox edit does to every cell, the catalogue and the tasks."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from tests.knowledge.test_libraries import THREE_FINGER

runner = CliRunner()
BUILTIN = service.builtin()
SCREWING_VACUUM = """@prefix pnp:  <http://plugnproduce.org/ontology#> .
@prefix owl:  <http://www.w3.org/2002/07/owl#> .
<http://example.org/screwing-vacuum> a owl:Ontology .
pnp:VacuumGripper <http://www.w3.org/2000/01/rdf-schema#subClassOf>
    [ a owl:Restriction ; owl:onProperty pnp:hasSkill ; owl:someValuesFrom pnp:CanScrew ] .
"""


def test_an_extension_that_changes_nothing_exits_0(tmp_path: Path) -> None:
    ext = tmp_path / "nothing.ttl"
    ext.write_text("@prefix owl: <http://www.w3.org/2002/07/owl#> .\n<http://example.org/n> a owl:Ontology .\n")
    result = runner.invoke(app, ["impact", str(ext)])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("no change")


def test_a_new_gripper_class_adds_offers_and_makes_a_task_plausible(tmp_path: Path) -> None:
    (tmp_path / "cells").mkdir()
    (tmp_path / "cells" / "robot-3f.yaml").write_text(
        f"cell: robot-3f\ndevices:\n  - {BUILTIN / 'devices' / 'robot.ttl'}\n"
        f"  - {THREE_FINGER / 'devices' / 'gripper-3f.ttl'}\n")
    result = runner.invoke(app, ["impact", str(THREE_FINGER / "ontology" / "three-finger.ttl"),
                                 "--cells", str(tmp_path / "cells"), "--json"])
    assert result.exit_code == 1, result.output
    doc = json.loads(result.stdout)
    cell = doc["cells"][0]
    assert {"command": "pick", "bindings": ["gripper=gripper-3f robot=robot"]} in cell["added"]
    assert {"task": str(BUILTIN / "tasks" / "pick-and-place.yaml"), "cell": str(tmp_path / "cells" / "robot-3f.yaml"),
            "plausible_before": False, "plausible_after": True} in doc["tasks"]


def test_a_catalogue_device_gaining_a_role_is_reported(tmp_path: Path) -> None:
    ext = tmp_path / "screwing-vacuum.ttl"
    ext.write_text(SCREWING_VACUUM)
    result = runner.invoke(app, ["impact", str(ext)])
    assert result.exit_code == 1
    assert "catalogue device vacuum-gripper: roles +screw.screwdriver" in result.stdout


def test_the_impact_of_a_loaded_library_s_own_ontology_file(tmp_path: Path) -> None:
    # The library is loaded (and its cell lists it): "before" is the knowledge without the file.
    cell = tmp_path / "robot-3f.yaml"
    cell.write_text(f"cell: robot-3f\nlibraries: [{THREE_FINGER}]\ndevices:\n  - {BUILTIN / 'devices' / 'robot.ttl'}\n"
                    f"  - {THREE_FINGER / 'devices' / 'gripper-3f.ttl'}\n")
    result = runner.invoke(app, ["--library", str(THREE_FINGER), "impact",
                                 str(THREE_FINGER / "ontology" / "three-finger.ttl"), "--cells", str(cell)])
    assert result.exit_code == 1, result.output
    assert "+ pick             gripper=gripper-3f robot=robot" in result.stdout
    assert "catalogue device gripper-3f: roles +" in result.stdout


def test_a_skill_axiom_is_reported_as_the_device_lacking_the_skill_s_mandatory_states(tmp_path: Path) -> None:
    ext = tmp_path / "screwing-vacuum.ttl"
    ext.write_text(SCREWING_VACUUM)
    result = runner.invoke(app, ["impact", str(ext)])
    assert result.exit_code == 1
    device = BUILTIN / "devices" / "vacuum-gripper.ttl"
    for state in ("Fastened", "ToolIdle"):
        assert (f"new violation: {device}:6: device vacuum-gripper has skill CanScrew but its Device State Chart "
                f"lacks the mandatory state '{state}'; expected a state annotated pnp:{state}") in result.stdout
    doc = json.loads(runner.invoke(app, ["impact", str(ext), "--json"]).stdout)
    assert [(v["file"], v["line"]) for v in doc["new_violations"]] == [(str(device), 6), (str(device), 6)]
    assert doc["cured_violations"] == []


def test_an_rdfxml_class_a_library_device_needs_cures_its_violation() -> None:
    # protege-lab is loaded; "before" is the knowledge without lab.owl, where its gripper's class is unknown.
    lab = Path(__file__).parents[1] / "data" / "libraries" / "protege-lab"
    result = runner.invoke(app, ["--library", str(lab), "impact", str(lab / "ontology" / "lab.owl"), "--json"])
    assert result.exit_code == 1, result.output
    doc = json.loads(result.stdout)
    cured = [v for v in doc["cured_violations"] if v["file"] == str(lab / "devices" / "soft-gripper.ttl")]
    assert [v["line"] for v in cured] == [8]
    assert "soft-gripper is of unknown class SoftGripper" in str(cured[0]["message"])
    assert doc["new_violations"] == []


def test_an_rdfxml_extension_brings_its_catalog_import(tmp_path: Path) -> None:
    # Not loaded as a library: the extension alone, whose OWL/XML import its library's catalog maps.
    lab = Path(__file__).parents[1] / "data" / "libraries" / "protege-lab"
    cell = tmp_path / "robot-soft.yaml"
    cell.write_text(f"cell: robot-soft\ndevices:\n  - {BUILTIN / 'devices' / 'robot.ttl'}\n"
                    f"  - {lab / 'devices' / 'soft-gripper.ttl'}\n")
    result = runner.invoke(app, ["impact", str(lab / "ontology" / "lab.owl"), "--cells", str(cell), "--json"])
    assert result.exit_code == 1, result.output
    added = json.loads(result.stdout)["cells"][0]["added"]
    assert {"command": "pick", "bindings": ["gripper=soft-gripper robot=robot"]} in added
