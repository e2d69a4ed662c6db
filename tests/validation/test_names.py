"""Names are checked, never dropped: unknown terms are findings at their line with "did you mean"."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from plugnproduce.cli import app
from plugnproduce.validation import validate_paths
from tests.conftest import edit

runner = CliRunner()


def _messages(path: Path) -> list[str]:
    return [str(p) for p in validate_paths([path]).sorted()]


def test_issue_11_a_misspelt_accepted_quantity_is_a_finding(device_copy) -> None:
    _, scxml = device_copy("gripper")
    edit(scxml, 'pnp:accepts="GripForce"', 'pnp:accepts="GripForse"')
    found = [m for m in _messages(scxml) if "GripForse" in m]
    assert len(found) == 1
    assert found[0].startswith(f"{scxml}:6: pnp:accepts: unknown quantity GripForse")
    assert found[0].endswith("did you mean GripForce?")


def test_a_misspelt_state_concept_is_a_finding(device_copy) -> None:
    _, scxml = device_copy("gripper")
    edit(scxml, 'pnp:concept="Closed"', 'pnp:concept="Clsoed"')
    found = [m for m in _messages(scxml) if "Clsoed" in m]
    assert found and "unknown state concept Clsoed" in found[0] and "did you mean Closed" in found[0]


def test_a_misspelt_device_class_is_named_at_its_line(device_copy) -> None:
    ttl, _ = device_copy("gripper")
    edit(ttl, "a pnp:ParallelGripper", "a pnp:ParalelGripper")
    messages = _messages(ttl)
    assert messages == [f"{ttl}:6: gripper is of unknown class ParalelGripper "
                        "(http://plugnproduce.org/ontology#ParalelGripper); did you mean pnp:ParallelGripper or pnp:Gripper "
                        "or pnp:MagneticGripper?"]


def test_issue_18_a_misspelt_device_class_in_a_cell_is_not_found_0(device_copy, tmp_path: Path) -> None:
    ttl, _ = device_copy("gripper")
    edit(ttl, "a pnp:ParallelGripper", "a pnp:ParalelGripper")
    cell = tmp_path / "cell.yaml"
    cell.write_text(f"cell: c\ndevices:\n  - {ttl}\n")
    result = runner.invoke(app, ["capabilities", "--cell", str(cell)])
    assert result.exit_code == 2
    assert result.output.startswith(f"{ttl}:6: gripper is of unknown class ParalelGripper")
    assert "found 0" not in result.output


def test_a_misspelt_required_skill_is_a_finding(process_copy) -> None:
    ttl, _ = process_copy("pick")
    edit(ttl, "pnp:requiresSkill pnp:CanGrip", "pnp:requiresSkill pnp:CanGirp")
    found = [m for m in _messages(ttl) if "CanGirp" in m]
    assert found and "requiresSkill: unknown skill CanGirp" in found[0] and "did you mean pnp:CanGrip" in found[0]


def test_a_misspelt_parameter_quantity_is_a_finding(process_copy) -> None:
    ttl, _ = process_copy("pick")
    edit(ttl, "pnp:quantity pnp:GripForce", "pnp:quantity pnp:GripForse")
    found = [m for m in _messages(ttl) if "GripForse" in m]
    assert found and "quantity: unknown quantity GripForse" in found[0]


def test_issue_18_a_turtle_syntax_error_is_one_line(device_copy) -> None:
    ttl, _ = device_copy("gripper")
    edit(ttl, "pnp:cost 1800 .", "pnp:cost 1800 1800 .")
    result = runner.invoke(app, ["validate", str(ttl)])
    assert result.exit_code == 2
    assert result.output.count("\n") == 1
    assert result.output.startswith(f"{ttl}:") and "malformed Turtle: expected" in result.output
    assert "b'" not in result.output


def test_class_axioms_in_a_device_file_say_where_they_belong(device_copy) -> None:
    ttl, _ = device_copy("gripper")
    line = ttl.read_text().count("\n") + 2
    ttl.write_text(ttl.read_text() + "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
                   "pnp:SoftGripper a owl:Class ; rdfs:subClassOf pnp:Gripper .\n")
    found = [m for m in _messages(ttl) if "SoftGripper" in m]
    assert found == [f"{ttl}:{line}: SoftGripper is an ontology term (Class); a description's class axioms are not "
                     "read: put them in a library's ontology/ folder"]


def test_a_misspelt_concept_in_a_process_chart_is_one_finding_with_did_you_mean(process_copy) -> None:
    ttl, scxml = process_copy("pick")
    edit(scxml, 'id="robot_lifted" pnp:concept="AtPose"', 'id="robot_lifted" pnp:concept="AtPsoe"')
    found = [m for m in _messages(ttl.parent) if "AtPsoe" in m]
    assert found == [f"{scxml}:18: state 'robot_lifted' is annotated with AtPsoe, which is not a state concept of "
                     "the ontology; did you mean AtPose or AtHome?"]
    assert not [m for m in _messages(ttl.parent) if m.startswith("<knowledge graph>")]


def test_a_misspelt_process_command_in_a_task_suggests_the_nearest(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text("task: t\nsteps:\n  - command: pik\n")
    assert _messages(task) == [f"{task}:3: step 1: unknown process command 'pik'; did you mean pick?"]
    result = runner.invoke(app, ["check", str(task), "--cell", str(Path(__file__).parents[2] / "descriptions" /
                                                                 "cells" / "bin-picking.yaml")])
    assert "unknown process command 'pik'; did you mean pick?" in result.stdout


GLUE = Path(__file__).parent.parent / "data" / "libraries" / "glue-dispensing"


def _glue_copy(tmp_path: Path) -> Path:
    library = tmp_path / "glue"
    for f in GLUE.rglob("*"):
        if f.is_file():
            (library / f.relative_to(GLUE)).parent.mkdir(parents=True, exist_ok=True)
            (library / f.relative_to(GLUE)).write_bytes(f.read_bytes())
    return library


def test_issue_29_a_library_concept_is_suggested_in_the_form_a_chart_takes(tmp_path: Path) -> None:
    library = _glue_copy(tmp_path)
    edit(library / "devices" / "dispenser.scxml", 'pnp:concept="http://example.org/glue#Dispensing"',
         'pnp:concept="gl:Dispensing"')
    edit(library / "processes" / "lay-bead.scxml", 'pnp:concept="http://example.org/glue#BeadLaid"',
         'pnp:concept="http://example.org/glue#BeadLayed"')
    messages = _messages(library)
    assert (f"{library}/devices/dispenser.scxml:8: pnp:concept: unknown state concept gl:Dispensing (gl:Dispensing); "
            "a chart does not expand prefixed names: write the full IRI; did you mean "
            "http://example.org/glue#Dispensing or Opening?") in messages
    assert (f"{library}/processes/lay-bead.scxml:9: state 'dispenser_laid' is annotated with BeadLayed, which is "
            "not a state concept of the ontology; did you mean http://example.org/glue#BeadLaid?") in messages


def test_issue_29_a_misspelt_library_quantity_in_turtle_is_suggested_by_its_prefixed_name(tmp_path: Path) -> None:
    library = _glue_copy(tmp_path)
    edit(library / "processes" / "lay-bead.ttl", "pnp:quantity gl:BeadLength", "pnp:quantity gl:BeadLenght")
    found = [m for m in _messages(library) if "BeadLenght" in m]
    assert found and found[0].endswith("did you mean gl:BeadLength?")


def test_issue_29_validate_prints_each_finding_once_from_a_relative_path(tmp_path: Path, monkeypatch) -> None:
    library = _glue_copy(tmp_path)
    edit(library / "devices" / "dispenser.scxml", 'pnp:concept="http://example.org/glue#Dispensing"',
         'pnp:concept="gl:Dispensing"')
    edit(library / "processes" / "lay-bead.scxml", 'pnp:concept="http://example.org/glue#BeadLaid"',
         'pnp:concept="BeadLayed"')
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["validate", "glue"])
    assert result.exit_code == 1
    lines = result.stdout.splitlines()
    assert all(line.startswith("glue/") for line in lines), lines
    assert [line.split(": ")[0] for line in lines] == [
        "glue/devices/dispenser.scxml:8", "glue/processes/lay-bead.scxml:9", "glue/processes/lay-bead.ttl:14"]
