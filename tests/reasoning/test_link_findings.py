"""The check of a task's data links, as a user reads it: each link that cannot get its value is one finding at the
line of the value, saying what is wrong, once however often the step runs."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.loader import load_device
from tests.conftest import edit
from tests.reasoning.test_flow_check import CELL, checked, line_of

LOCALIZE = "  - name: localize\n    command: localize-part\n"


def _links(tmp_path: Path, text: str) -> list[tuple[int, int, str]]:
    result, path = checked(tmp_path, text)
    assert not result.plausible
    return [(p.step, p.where.line, p.text) for p in result.problems if p.kind == "bad_link"]


def test_a_link_to_a_name_no_step_has_lists_that_no_step_is_named(tmp_path: Path) -> None:
    text = "task: unnamed\nsteps:\n  - command: localize-part\n  - command: pick\n" \
           "    params:\n      pick_pose: {from: localize, output: part_pose}\n"
    assert _links(tmp_path, text) == [(2, 6, "step 2 (pick): parameter pick_pose takes part_pose from localize, but "
                                             "no step is named 'localize'; named steps: none")]


def test_a_step_taking_its_own_output_is_refused_as_coming_after_it(tmp_path: Path) -> None:
    text = "task: own\nsteps:\n  - name: again\n    command: localize-part\n" \
           "  - name: pick\n    command: pick\n    params:\n      pick_pose: {from: pick, output: part_pose}\n"
    assert _links(tmp_path, text) == [(2, 8, "step 2 (pick): parameter pick_pose takes part_pose from pick, but "
                                             "step 2 (pick) comes after it; a value must be produced first")]


@pytest.mark.parametrize("repeat", ["", "repeat: 3\n"])
def test_a_wrong_link_in_the_last_step_is_one_finding_however_often_the_task_runs(tmp_path: Path,
                                                                                   repeat: str) -> None:
    text = f"task: last\n{repeat}steps:\n{LOCALIZE}  - command: pick\n" \
           "    params:\n      pick_pose: {from: localize, output: part_type}\n"
    [(step, line, said)] = _links(tmp_path, text)
    assert (step, line) == (2, line_of(tmp_path / "task.yaml", "pick_pose:"))
    assert said == ("step 2 (pick): parameter pick_pose takes part_type from localize, a string; the parameter "
                    "takes a Pose")


def test_an_offset_on_an_output_that_is_no_pose_is_refused_at_the_value(tmp_path: Path) -> None:
    text = f"task: offset\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_type, offset: [0, 0, 0.1, 0, 0, 0]}\n"
    assert _links(tmp_path, text) == [(2, 7, "step 2 (pick): parameter pick_pose takes part_type from localize "
                                             "with an offset, but part_type is a string; only a pose takes an "
                                             "offset [x, y, z, rx, ry, rz]")]


def test_a_wrong_link_in_a_loop_is_one_finding_not_one_per_iteration(tmp_path: Path) -> None:
    text = ("task: looped\nsteps:\n  - loop:\n      until: BinEmpty\n      max: 5\n      steps:\n"
            "        - name: localize\n          command: localize-part\n        - command: pick\n"
            "          params:\n            pick_pose: {from: localize, output: pose}\n        - command: place\n")
    [(step, line, said)] = _links(tmp_path, text)
    assert (step, line) == (2, 11) and said.endswith("localize-part gives back no 'pose'; its outputs: part_pose, "
                                                     "part_type")


def _bad_links(result: service.reasoning.CheckResult) -> list[tuple[int, int | None, str]]:
    return [(p.step, p.where.line, p.text) for p in result.problems if p.kind == "bad_link"]


LOCALIZE_IN_LOOP = ("task: pipelined\nsteps:\n  - loop:\n      until: BinEmpty\n      max: 3\n      steps:\n"
                    "        - name: localize\n          command: localize-part\n"
                    "        - command: pick-and-place\n          params:\n"
                    "            pick_pose: {from: localize, output: part_pose}\n"
                    "            place_pose: [0.60, -0.20, 0.10, 0, 180, 0]\n")


def test_a_link_in_a_loop_to_the_step_just_before_it_is_plausible(tmp_path: Path) -> None:
    result, _ = checked(tmp_path, LOCALIZE_IN_LOOP)
    assert result.plausible, [str(p) for p in result.problems]


def test_a_wrong_link_right_after_a_loop_is_found(tmp_path: Path) -> None:
    text = LOCALIZE_IN_LOOP + "  - command: pick\n    params:\n      pick_pose: {from: localize, output: part_type}\n"
    result, path = checked(tmp_path, text)
    assert _bad_links(result) == [(5, line_of(path, "pick_pose: {from: localize, output: part_type}"),
                                   "step 5 (pick): parameter pick_pose takes part_type from localize, a string; "
                                   "the parameter takes a Pose")]


def test_a_link_on_a_parameter_the_process_does_not_declare_is_an_unknown_parameter(tmp_path: Path) -> None:
    text = f"task: undeclared\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_pose}\n      approach: {from: localize, output: part_pose}\n"
    result, path = checked(tmp_path, text)
    assert not result.plausible
    assert [(p.step, p.command, p.kind, p.parameter, p.where.line, p.text) for p in result.problems] == [
        (2, "pick", "unknown_param", "approach", line_of(path, "approach:"), "step 2 (pick): parameter approach is "
         "not declared by pick (its parameters: grip_force, lift_pose, pick_pose, speed)")]


def test_a_wrong_link_is_found_after_an_unknown_command_and_beside_an_unknown_parameter(tmp_path: Path) -> None:
    text = (f"task: beside\nsteps:\n{LOCALIZE}  - command: polish\n  - command: pick\n    params:\n"
            "      approach: {from: localize, output: part_pose}\n"
            "      pick_pose: {from: localize, output: part_type}\n")
    result, path = checked(tmp_path, text)
    assert {p.kind for p in result.problems} == {"unknown_command", "unknown_param", "bad_link"}
    assert _bad_links(result) == [(3, line_of(path, "pick_pose:"), "step 3 (pick): parameter pick_pose takes "
                                   "part_type from localize, a string; the parameter takes a Pose")]


def test_a_link_from_a_step_of_an_unknown_command_is_only_the_unknown_command(tmp_path: Path) -> None:
    text = "task: unknown-source\nsteps:\n  - name: polish\n    command: polish\n  - command: pick\n" \
           "    params:\n      pick_pose: {from: polish, output: part_pose}\n"
    result, _ = checked(tmp_path, text)
    assert [(p.step, p.kind) for p in result.problems] == [(1, "unknown_command")]


def test_a_link_from_a_step_without_outputs_says_it_has_none(tmp_path: Path) -> None:
    text = "task: no-outputs\nsteps:\n  - name: home\n    command: move-to\n" \
           "    params: {target_pose: [0.30, 0.00, 0.40, 0, 180, 0]}\n  - command: pick\n" \
           "    params:\n      pick_pose: {from: home, output: part_pose}\n"
    assert _links(tmp_path, text) == [(2, 8, "step 2 (pick): parameter pick_pose takes part_pose from home, but "
                                             "move-to gives back no 'part_pose'; its outputs: none")]


def test_a_link_to_a_name_no_step_has_lists_the_named_steps(tmp_path: Path) -> None:
    text = f"task: misnamed\nsteps:\n{LOCALIZE}  - name: home\n    command: move-to\n" \
           "    params: {target_pose: [0.30, 0.00, 0.40, 0, 180, 0]}\n  - command: pick\n" \
           "    params:\n      pick_pose: {from: localise, output: part_pose}\n"
    assert _links(tmp_path, text) == [(3, 10, "step 3 (pick): parameter pick_pose takes part_pose from localise, "
                                              "but no step is named 'localise'; named steps: home, localize")]


def test_a_link_to_a_step_only_a_branch_in_a_loop_runs_names_its_last_copy(tmp_path: Path) -> None:
    text = ("task: found-in-a-loop\nsteps:\n  - loop:\n      until: BinEmpty\n      max: 3\n      steps:\n"
            "        - command: localize-part\n          on:\n            PartFound:\n"
            "              - name: again\n                command: localize-part\n"
            "  - command: pick\n    params:\n      pick_pose: {from: again, output: part_pose}\n")
    result, path = checked(tmp_path, text)
    assert _bad_links(result) == [(5, line_of(path, "pick_pose:"), "step 5 (pick): parameter pick_pose takes "
                                   "part_pose from again, but step 4 (again) runs only on branch PartFound at step 3; "
                                   "a step may take only an output produced on every path to it")]


def test_a_bad_link_is_told_as_json_with_its_command_terms_and_place(tmp_path: Path) -> None:
    text = f"task: json\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_type}\n"
    result, path = checked(tmp_path, text)
    [told] = [p.to_json() for p in result.problems if p.kind == "bad_link"]
    assert {k: told[k] for k in ("step", "command", "kind", "where", "parameter", "iris", "rests_on")} == {
        "step": 2, "command": "pick", "kind": "bad_link", "where": f"{path}:7", "parameter": "pick_pose",
        "iris": ["http://www.w3.org/2001/XMLSchema#string", "http://plugnproduce.org/ontology#Pose"],
        "rests_on": [f"{path}:7"]}


PART_FINDING = Path(__file__).parents[1] / "data" / "libraries" / "part-finding"
"""A library written outside the package whose own process find-part gives back part_pose and part_type."""

FOUND_THEN = "task: found\nsteps:\n  - name: found\n    command: find-part\n"


def _part_finding(tmp_path: Path, old: str, new: str) -> Path:
    """The part-finding library with one edit of its find-part process."""
    library = tmp_path / "part-finding"
    shutil.copytree(PART_FINDING, library)
    edit(library / "processes" / "find-part.ttl", old, new)
    return library


def _library_links(library: Path, text: str) -> list[tuple[int, int | None, str]]:
    path = library / "tasks" / "linked.yaml"
    path.write_text(text, encoding="utf-8")
    result = service.check(path, CELL, service.knowledge((library,)))
    assert not result.plausible
    return _bad_links(result)


def test_a_pose_given_back_without_a_unit_does_not_fit_a_parameter_in_m_deg(tmp_path: Path) -> None:
    library = _part_finding(tmp_path, 'pnp:datatype pnp:Pose ;\n    pnp:unit "m deg" .',
                            'pnp:datatype pnp:Pose ;\n    pnp:unit "" .')
    text = FOUND_THEN + "  - command: pick\n    params:\n      pick_pose: {from: found, output: part_pose}\n"
    assert _library_links(library, text) == [(2, 7, "step 2 (pick): parameter pick_pose takes part_pose from found "
                                                    "in no unit; the parameter is in m deg")]


def test_a_value_given_back_in_a_unit_does_not_fit_a_parameter_without_one(tmp_path: Path) -> None:
    library = _part_finding(tmp_path, 'pnp:datatype xsd:string ;\n    pnp:unit "" .\n',
                            'pnp:datatype xsd:string ;\n    pnp:unit "mm" .\n')
    text = FOUND_THEN + "  - command: find-part\n    params:\n      part_type: {from: found, output: part_type}\n"
    assert _library_links(library, text) == [(2, 7, "step 2 (find-part): parameter part_type takes part_type from "
                                                    "found in mm; the parameter is in no unit")]


def test_a_pose_of_the_librarys_own_quantity_does_not_fit_a_target_pose(tmp_path: Path) -> None:
    library = _part_finding(tmp_path, "pnp:quantity pnp:TargetPose ;", "pnp:quantity pf:GraspPose ;")
    edit(library / "processes" / "find-part.ttl", "@prefix xsd:",
         "@prefix pf: <http://example.org/part-finding#> .\n@prefix xsd:")
    ontology = library / "ontology" / "part-finding.ttl"
    ontology.write_text(ontology.read_text(encoding="utf-8") + '\npf:GraspPose a owl:Class ; '
                        'rdfs:subClassOf pnp:Quantity ; rdfs:label "grasp pose" .\n', encoding="utf-8")
    text = FOUND_THEN + "  - command: pick\n    params:\n      pick_pose: {from: found, output: part_pose}\n"
    assert _library_links(library, text) == [(2, 7, "step 2 (pick): parameter pick_pose takes part_pose from found, "
                                                    "a grasp pose; the parameter takes a target pose")]


POSE_PARAM = '<param name="part_pose" expr="part_pose" pnp:maxReach="1.2"/>'


def _silent_cell(tmp_path: Path, internal: bool = False) -> service.Cell:
    """The paper's cell with a bin-picking PC whose PartLocalized event carries no part_pose; ``internal``: its
    chart still sends the pose, on an event of its own that no controller receives."""
    folder = tmp_path / "silent"
    folder.mkdir()
    for f in ("binpicking-pc.ttl", "binpicking-pc.scxml"):
        shutil.copy(service.builtin("devices", f), folder)
    edit(folder / "binpicking-pc.scxml", POSE_PARAM, "")
    if internal:
        edit(folder / "binpicking-pc.scxml", '<onentry><send event="localize.done" delay="150ms"/></onentry>',
             '<onentry><send event="localize.done" delay="150ms"/>'
             '<send event="localize.pose"><param name="part_pose" expr="part_pose"/></send></onentry>')
    silent = load_device(folder / "binpicking-pc.ttl", service.knowledge().taxonomy)
    return service.cell(CELL).with_device(silent)


def _unreported(tmp_path: Path, text: str, cell: service.Cell | None = None) -> list[tuple[int, str | None, str]]:
    path = tmp_path / "task.yaml"
    path.write_text(text, encoding="utf-8")
    result = service.check(path, cell or _silent_cell(tmp_path))
    assert not result.plausible
    return [(p.step, p.parameter, p.text) for p in result.problems if p.kind == "bad_link" and p.device]


def _never(step: int, command: str, parameter: str = "pick_pose") -> str:
    return (f"step {step} ({command}): parameter {parameter} takes part_pose from localize, but device "
            "'binpicking-pc' (role 'localizer') reports no part_pose: no event of its chart carries a value of "
            "that name")


def test_a_link_in_a_straight_task_to_an_output_the_device_never_reports_is_refused(tmp_path: Path) -> None:
    text = f"task: straight\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_pose}\n"
    assert _unreported(tmp_path, text) == [(2, "pick_pose", _never(2, "pick"))]


def test_an_unreported_output_is_found_in_the_loops_first_iteration_and_right_after_the_loop(tmp_path: Path) -> None:
    after = "  - command: pick-and-place\n    params:\n      pick_pose: {from: localize, output: part_pose}\n" \
            "      place_pose: [0.60, -0.20, 0.10, 0, 180, 0]\n"
    assert _unreported(tmp_path, LOCALIZE_IN_LOOP + after) == [
        (2, "pick_pose", "loop iteration 1: " + _never(2, "pick-and-place")),
        (5, "pick_pose", _never(5, "pick-and-place"))]


def test_a_link_to_a_later_step_whose_device_never_reports_it_says_both(tmp_path: Path) -> None:
    text = "task: late\nsteps:\n  - command: pick\n    params:\n      pick_pose: {from: localize, output: part_pose}\n" \
           f"{LOCALIZE}"
    result, _ = checked(tmp_path, text)
    silent = service.check(tmp_path / "task.yaml", _silent_cell(tmp_path))
    assert [p.text for p in silent.problems if p.kind == "bad_link"] == [
        *(p.text for p in result.problems if p.kind == "bad_link"), _never(1, "pick")]


def test_an_unreported_output_is_found_beside_a_link_to_an_output_the_process_lacks(tmp_path: Path) -> None:
    text = f"task: two-links\nsteps:\n{LOCALIZE}  - command: pick-and-place\n    params:\n" \
           "      pick_pose: {from: localize, output: pose}\n      place_pose: {from: localize, output: part_pose}\n"
    assert _unreported(tmp_path, text) == [(2, "place_pose", _never(2, "pick-and-place", "place_pose"))]


def test_a_value_sent_only_on_an_event_of_the_devices_own_is_not_reported(tmp_path: Path) -> None:
    text = f"task: internal\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_pose}\n"
    assert _unreported(tmp_path, text, _silent_cell(tmp_path, internal=True)) == [(2, "pick_pose", _never(2, "pick"))]


def test_a_link_from_a_step_no_device_can_localize_for_is_no_finding_beside_an_unreported_one(tmp_path: Path) -> None:
    text = ("task: two-sources\nsteps:\n  - name: elsewhere\n    command: localize-part\n"
            "    bind: {localizer: other-pc}\n" + LOCALIZE + "  - command: pick-and-place\n    params:\n"
            "      pick_pose: {from: elsewhere, output: part_pose}\n      place_pose: {from: localize, output: part_pose}\n")
    path = tmp_path / "task.yaml"
    path.write_text(text, encoding="utf-8")
    result = service.check(path, _silent_cell(tmp_path))
    assert [(p.step, p.kind, p.parameter) for p in result.problems] == [(1, "absent", None),
                                                                        (3, "bad_link", "place_pose")]
    assert result.problems[1].text == _never(3, "pick-and-place", "place_pose")


def test_an_unreported_output_is_told_as_json_with_the_value_and_the_device_it_rests_on(tmp_path: Path) -> None:
    text = f"task: json\nsteps:\n{LOCALIZE}  - command: pick\n    params:\n" \
           "      pick_pose: {from: localize, output: part_pose}\n"
    path = tmp_path / "task.yaml"
    path.write_text(text, encoding="utf-8")
    cell = _silent_cell(tmp_path)
    [told] = [p.to_json() for p in service.check(path, cell).problems]
    device = next(d for d in cell.devices if d.id == "binpicking-pc")
    assert {k: told[k] for k in ("step", "command", "kind", "where", "role", "device", "parameter", "iris",
                                 "rests_on")} == {
        "step": 2, "command": "pick", "kind": "bad_link", "where": f"{path}:7", "role": "localizer",
        "device": "binpicking-pc", "parameter": "pick_pose", "iris": [], "rests_on": [f"{path}:7", str(device.where)]}
    assert str(device.where).startswith(str(tmp_path / "silent" / "binpicking-pc.ttl"))
