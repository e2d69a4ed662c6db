"""The values a Specific Process State Chart sends: each request's arguments as the generated chart writes them
(converted to the device's unit, a pose relative to a reported one, the defaults), and the states between."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from lxml import etree
from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.drawing import chart_to_dot
from plugnproduce.executor.chartmap import StateInfo, chart_map
from plugnproduce.statechart import parse_chart
from tests.conftest import edit

NS = {"s": "http://www.w3.org/2005/07/scxml"}
LIBRARIES = Path(__file__).parents[1] / "data" / "libraries"
CELL = service.builtin("cells", "bin-picking.yaml")


def sends(task: Path, cell: Path, libraries: tuple[Path, ...] = ()) -> list[tuple[str, str, list[tuple[str, str]]]]:
    """Each request of the task chart: the controller state it leaves, its event and its (argument, expr) pairs."""
    generation = service.generation(task, cell, knowledge=service.knowledge(libraries))
    assert generation.check.plausible, [str(p) for p in generation.check.problems]
    tree = etree.fromstring(next(c.data for c in generation.charts if c.kind == "task"))
    return [(s.getparent().getparent().get("id"), s.get("event"), [(p.get("name"), p.get("expr")) for p in s])
            for s in tree.iterfind(".//s:send", NS) if ".request." in (s.get("event") or "")]


def test_a_force_in_newtons_is_sent_in_the_kilonewtons_the_device_takes(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text("task: close-in-kn\nsteps:\n  - command: close-gripper\n    params: {grip_force: 45}\n"
                    "  - command: move-to\n  - command: open-gripper\n", encoding="utf-8")
    library = LIBRARIES / "kilonewton-gripper"
    assert sends(task, library / "cells" / "bin-picking-kn.yaml", (library,)) == [
        ("s1_kn_gripper_open", "xirp.request.Close", [("GripForce", "0.045")]),
        # the process's own defaults: the speed a number, the pose written as text in the ontology
        ("s2_robot_idle", "xirp.request.MoveTo", [("Speed", "50"), ("TargetPose", "[0.30, 0.00, 0.40, 0, 180, 0]")]),
        ("s3_kn_gripper_closed", "xirp.request.Open", [])]


def test_a_pose_relative_to_a_reported_one_is_the_reported_pose_plus_its_offset() -> None:
    found = "pnp_out_localize_part_pose"
    lifted = "[" + ", ".join(f"{found}[{i}] + {o}" for i, o in enumerate((0.0, 0.0, 0.2, 0.0, 0.0, 0.0))) + "]"
    requests = sends(LIBRARIES / "relative-lift" / "tasks" / "lift-with-the-part.yaml", CELL)
    assert requests[:6] == [
        ("s1_binpicking_pc_ready", "upnp.request.Localize", [("PartType", "'bracket'")]),
        ("s1_sensor3d_ready", "upnp.request.Capture", [("Exposure", "25")]),
        ("s2_gripper_open", "xirp.request.Close", [("GripForce", "45")]),
        ("s2_robot_idle", "xirp.request.MoveTo", [("TargetPose", found), ("Speed", "50")]),
        ("s2_robot_at_part", "xirp.request.MoveTo", [("TargetPose", lifted), ("Speed", "50")]),
        ("s3_gripper_closed", "xirp.request.Open", [])]
    assert ("s3_robot_idle", "xirp.request.MoveTo", [("TargetPose", "[0.6, -0.2, 0.1, 0, 180, 0]"),
                                                     ("Speed", "80")]) in requests


@pytest.mark.parametrize(("value", "expr"), [
    ("[0.55, -0.25, 0.1, 0, 180, 0]", "[0.55, -0.25, 0.1, 0, 180, 0]"),
    ('"0.55 -0.25 0.1 0 180 0"', "[0.55, -0.25, 0.1, 0, 180, 0]"),
])
def test_a_pose_written_as_a_list_or_as_text_is_sent_as_a_list(tmp_path: Path, value: str, expr: str) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(f"task: pose\nsteps:\n  - command: move-to\n    params: {{target_pose: {value}, speed: 30}}\n",
                    encoding="utf-8")
    assert sends(task, CELL) == [("s1_robot_idle", "xirp.request.MoveTo", [("Speed", "30"), ("TargetPose", expr)])]


def test_a_library_request_takes_its_length_in_millimetres_and_the_glue_it_is_not_given(tmp_path: Path) -> None:
    library = LIBRARIES / "glue-dispensing"
    task = tmp_path / "task.yaml"
    task.write_text("task: glue\nsteps:\n  - command: lay-bead\n    params: {length: 12 cm}\n", encoding="utf-8")
    assert sends(task, library / "cells" / "glue-cell.yaml", (library,)) == [
        ("s1_dispenser_ready", "upnp.request.Dispense", [("GlueKind", "'epoxy'"), ("BeadLength", "120.0")])]


def test_a_text_of_six_words_that_are_no_numbers_is_sent_as_text(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text("task: words\nsteps:\n  - command: localize-part\n"
                    "    params: {exposure: 25, part_type: big red bracket with two holes}\n", encoding="utf-8")
    assert sends(task, CELL)[0] == ("s1_binpicking_pc_ready", "upnp.request.Localize",
                                    [("PartType", "'big red bracket with two holes'")])


def test_a_library_process_whose_states_do_not_begin_with_the_role_keeps_their_names(tmp_path: Path) -> None:
    # a library's squeeze: the close-gripper process with its general states named jaws_open and jaws_closed
    processes = tmp_path / "squeezing" / "processes"
    processes.mkdir(parents=True)
    for suffix in (".ttl", ".scxml"):
        text = service.builtin("processes", "close-gripper" + suffix).read_text(encoding="utf-8")
        text = text.replace("close-gripper", "squeeze").replace("gripper_open", "jaws_open")
        (processes / ("squeeze" + suffix)).write_text(text.replace("gripper_closed", "jaws_closed"), encoding="utf-8")
    task = tmp_path / "task.yaml"
    task.write_text("task: squeeze\nsteps:\n  - command: squeeze\n    params: {grip_force: 45}\n", encoding="utf-8")
    assert sends(task, CELL, (tmp_path / "squeezing",)) == [
        ("s1_gripper_jaws_open", "xirp.request.Close", [("GripForce", "45")])]


def test_the_journal_reads_each_state_of_a_region_as_its_devices_state() -> None:
    # what the executor tells of each controller state of the localisation: its device and the device's state
    generation = service.generation(service.builtin("tasks", "bin-picking-localized.yaml"), CELL)
    data = next(c.data for c in generation.charts if c.kind == "task")
    states = chart_map(parse_chart(data, "task.scxml"))
    found = {k: v for k, v in states.items() if k.startswith("s1_binpicking")}
    assert found == {f"s1_binpicking_pc{name}": StateInfo("binpicking-pc", state, "localize-part", False)
                     for name, state in (("", None), ("_ready", "ready"), ("_localizing", "localizing"),
                                         ("_done", "localized"))}
    # the pick's gripper: between sending Close and the event that it closed, the state the device is in
    assert {k: v.device_state for k, v in states.items() if k.startswith("s2_gripper")} == {
        "s2_gripper": None, "s2_gripper_open": "open", "s2_gripper_closed_1a": "closing", "s2_gripper_closed": "closed"}
    region = etree.fromstring(data).find(".//s:state[@id='s1_binpicking_pc']", NS)
    pnp = "{http://plugnproduce.org/ontology#}"
    assert (region.get(pnp + "role"), region.get(pnp + "device")) == ("localizer", "binpicking-pc")


def test_each_mirrored_move_of_a_region_leads_to_its_next_state() -> None:
    # the pick's gripper, once the robot is at the part: send Close and go to the state of a closing gripper, then
    # wait there for the event that it closed and go on to the region's final state
    generation = service.generation(service.builtin("tasks", "bin-picking-localized.yaml"), CELL)
    chart = etree.fromstring(next(c.data for c in generation.charts if c.kind == "task"))
    region = chart.find(".//s:state[@id='s2_gripper']", NS)
    assert [(s.get("id"), [(t.get("event"), t.get("cond"), [a.get("event") for a in t], t.get("target"))
                           for t in s.iterfind("s:transition", NS)]) for s in region] == [
        ("s2_gripper_open", [(None, "In('s2_robot_at_part')", ["xirp.request.Close"], "s2_gripper_closed_1a")]),
        ("s2_gripper_closed_1a", [("gripper.xirp.event.gripper_closed", None, [], "s2_gripper_closed")]),
        ("s2_gripper_closed", [])]


def test_a_force_for_a_device_that_declares_no_unit_is_sent_as_written(tmp_path: Path) -> None:
    # the gripper's Close takes a plain number: the 45 N of the task go out as 45, not converted to a float
    for f in ("gripper.ttl", "gripper.scxml"):
        shutil.copy(service.builtin("devices", f), tmp_path)
    edit(tmp_path / "gripper.ttl", 'pnp:unit "N" ;\n    pnp:minValue 20', 'pnp:unit "" ;\n    pnp:minValue 20')
    cell = service.cell(CELL).with_device(load_device(tmp_path / "gripper.ttl", service.knowledge().taxonomy))
    task = tmp_path / "task.yaml"
    task.write_text("task: plain\nsteps:\n  - command: close-gripper\n    params: {grip_force: 45}\n", encoding="utf-8")
    generation = service.generation(task, cell)
    chart = etree.fromstring(next(c.data for c in generation.charts if c.kind == "task"))
    assert [(p.get("name"), p.get("expr")) for p in chart.iterfind(".//s:send/s:param", NS)] == [("GripForce", "45")]


def test_the_cycle_time_follows_each_regions_path_and_its_synchronisation(tmp_path: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    # the localizer waits for the sensor's capture (180 ms) before localizing (150 ms); a pick moves the robot
    # (250 ms), closes the gripper (120 ms) once there, and lifts (250 ms)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))  # estimated from the charts, not read back as kept
    estimate = service.cycle_time(service.builtin("tasks", "bin-picking-localized.yaml"), CELL)
    assert estimate is not None
    assert [(s.step, s.command, round(s.seconds, 6)) for s in estimate.steps[:3]] == [
        (1, "localize-part", 0.33), (2, "pick", 0.62), (3, "place", 0.62)]


def test_a_general_transition_the_device_needs_no_move_for_goes_straight_on(tmp_path: Path) -> None:
    # the holding library's hold: from AtPose to AtPose once the gripper is open, after a move-to
    task = tmp_path / "task.yaml"
    task.write_text("task: hold\nsteps:\n  - command: move-to\n  - command: hold\n", encoding="utf-8")
    generation = service.generation(task, CELL, knowledge=service.knowledge((LIBRARIES / "holding",)))
    chart = etree.fromstring(next(c.data for c in generation.charts if c.kind == "task"))
    there = chart.find(".//s:state[@id='s2_robot_there']", NS)
    assert [(t.get("event"), t.get("cond"), t.get("target")) for t in there] == [
        (None, "In('s2_gripper_open')", "s2_robot_still")]
    # the gripper's role has one state: it is done at once
    assert chart.find(".//s:state[@id='s2_gripper']/s:final[@id='s2_gripper_open']", NS) is not None
    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", next(c.data for c in generation.charts if c.kind == "closed-world").decode())
    assert set(processor.start().configuration_values) == {"done"}


def test_an_argument_the_process_does_not_supply_takes_the_devices_own_default(tmp_path: Path) -> None:
    # the glue library with no default glue in its process: the dispenser's own default (here acrylic) goes out
    library = tmp_path / "glue-dispensing"
    shutil.copytree(LIBRARIES / "glue-dispensing", library)
    edit(library / "devices" / "dispenser.ttl", 'pnp:defaultValue "epoxy"', 'pnp:defaultValue "acrylic"')
    edit(library / "processes" / "lay-bead.ttl", 'pnp:unit "" ;   # a text has no unit: ""\n    pnp:defaultValue "epoxy" .',
         'pnp:unit "" .')
    task = tmp_path / "task.yaml"
    task.write_text("task: glue\nsteps:\n  - command: lay-bead\n    params: {length: 12 cm}\n", encoding="utf-8")
    assert sends(task, library / "cells" / "glue-cell.yaml", (library,)) == [
        ("s1_dispenser_ready", "upnp.request.Dispense", [("BeadLength", "120.0"), ("GlueKind", "'acrylic'")])]


def test_the_generated_program_lists_each_devices_requests_and_events_in_order() -> None:
    commands = service.generate(service.builtin("tasks", "bin-picking.yaml"), CELL).task.commands()
    first = [(device, c.kind, c.name) for step, device, c in commands if step == 2]
    assert first == [("gripper", "request", "Open"), ("gripper", "event", "gripper_opened"),
                     ("robot", "request", "MoveTo"), ("robot", "event", "motion_done"),
                     ("robot", "request", "MoveTo"), ("robot", "event", "motion_done")]
    assert len(commands) == 48


def test_the_picture_of_a_steps_chart_names_each_controller_states_concept() -> None:
    # pnp draw of the pick step: each state of a region shows the general state's concept it stands for
    generation = service.generation(service.builtin("tasks", "bin-picking-localized.yaml"), CELL)
    chart = parse_chart(next(c.data for c in generation.charts if c.name == "step02-pick.scxml"), "pick.scxml")
    labels = re.findall(r'label="(s2_\w+)\\n«(\w+)»"', chart_to_dot(chart).source)
    assert labels == [("s2_gripper_open", "Open"), ("s2_gripper_closed", "Closed"), ("s2_robot_idle", "Idle"),
                      ("s2_robot_approach", "Moving"), ("s2_robot_at_part", "AtPose"), ("s2_robot_lift", "Moving"),
                      ("s2_robot_lifted", "AtPose")]


def test_a_region_that_waits_for_another_sends_its_first_request_only_once_the_other_is_there() -> None:
    # the pick: the gripper closes only once the robot is at the part, then waits for the event that it closed
    generation = service.generation(service.builtin("tasks", "bin-picking-localized.yaml"), CELL)
    chart = etree.fromstring(next(c.data for c in generation.charts if c.kind == "task"))
    moves = [(t.get("cond"), t.get("event"), [s.get("event") for s in t.iterfind("s:send", NS)], t.get("target"))
             for state in ("s2_gripper_open", "s2_gripper_closed_1a")
             for t in chart.iterfind(f".//s:state[@id='{state}']/s:transition", NS)]
    assert moves == [("In('s2_robot_at_part')", None, ["xirp.request.Close"], "s2_gripper_closed_1a"),
                     (None, "gripper.xirp.event.gripper_closed", [], "s2_gripper_closed")]
