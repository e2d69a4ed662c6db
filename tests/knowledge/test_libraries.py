"""Libraries: a user's ontology extension, devices and processes used as the built-in ones are."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.errors import DescriptionError
from plugnproduce.knowledge import Library, builtin_library, load_knowledge

DATA = Path(__file__).parent / "data"
THREE_FINGER = DATA / "three-finger"
BUILTIN = service.builtin()
TF = "http://example.org/three-finger#"
runner = CliRunner()


def bin_picking_cell(folder: Path, libraries: list[Path] | None = None, gripper: Path | None = None) -> Path:
    """The built-in bin-picking cell, its gripper swapped for ``gripper``, listing ``libraries``."""
    devices = [BUILTIN / "devices" / "robot.ttl", gripper or BUILTIN / "devices" / "gripper.ttl",
               BUILTIN / "devices" / "sensor3d.ttl", BUILTIN / "devices" / "binpicking-pc.ttl"]
    text = "cell: bin-picking-3f\n"
    if libraries:
        text += "libraries:\n" + "".join(f"  - {p}\n" for p in libraries)
    text += "devices:\n" + "".join(f"  - {d}\n" for d in devices)
    path = folder / "cell.yaml"
    path.write_text(text)
    return path


@pytest.fixture()
def three_finger_cell(tmp_path: Path) -> Path:
    return bin_picking_cell(tmp_path, [THREE_FINGER], THREE_FINGER / "devices" / "gripper-3f.ttl")


def test_a_user_gripper_class_is_offered_pick_in_the_bin_picking_cell(three_finger_cell: Path) -> None:
    offered = service.capabilities(three_finger_cell).commands()
    assert {"pick", "pick-and-place", "bin-pick", "squeeze"} <= set(offered)


def test_a_skill_in_the_library_namespace_keeps_its_namespace() -> None:
    k = service.knowledge((THREE_FINGER,))
    skills = k.taxonomy.implied_skills[TF + "ThreeFingerGripper"]
    assert TF + "CanAdaptiveGrip" in skills
    assert "http://plugnproduce.org/ontology#CanAdaptiveGrip" not in skills


def test_two_taxonomies_side_by_side(three_finger_cell: Path) -> None:
    builtin, extended = service.knowledge(), service.knowledge((THREE_FINGER,))
    assert not builtin.taxonomy.knows(TF + "ThreeFingerGripper")
    assert extended.taxonomy.knows(TF + "ThreeFingerGripper")
    assert "squeeze" not in [p.id for p in builtin.processes]
    assert "squeeze" in [p.id for p in extended.processes]
    assert service.knowledge() is builtin  # loading again gives the same knowledge, nothing was replaced


def test_library_option_and_environment_give_the_same_offer(tmp_path: Path) -> None:
    cell = bin_picking_cell(tmp_path, gripper=THREE_FINGER / "devices" / "gripper-3f.ttl")
    without = runner.invoke(app, ["capabilities", "--cell", str(cell)])
    assert without.exit_code == 2 and "unknown class ThreeFingerGripper" in without.output
    by_option = runner.invoke(app, ["--library", str(THREE_FINGER), "capabilities", "--cell", str(cell)])
    by_env = runner.invoke(app, ["capabilities", "--cell", str(cell)], env={"PNP_LIBRARY": f"{THREE_FINGER}:"})
    assert by_option.exit_code == 0, by_option.output
    assert "squeeze          gripper=gripper-3f robot=robot" in by_option.stdout
    assert by_env.stdout == by_option.stdout


def test_no_builtin_leaves_the_builtin_processes_out() -> None:
    result = runner.invoke(app, ["--no-builtin", "--library", str(THREE_FINGER), "capabilities", "--cell",
                                 str(BUILTIN / "cells" / "bin-picking.yaml")])
    assert result.exit_code == 0, result.output
    assert "1 of 1 process commands offered" in result.stdout and "squeeze" in result.stdout


def test_a_missing_library_folder_is_bad_input(tmp_path: Path) -> None:
    result = runner.invoke(app, ["--library", str(tmp_path / "nope"), "capabilities", "--cell",
                                 str(BUILTIN / "cells" / "bin-picking.yaml")])
    assert result.exit_code == 2 and "library folder not found" in result.output


def test_library_devices_join_the_catalogue() -> None:
    k = service.knowledge((THREE_FINGER,))
    assert "gripper-3f" in [d.id for d in service.catalogue(knowledge=k)]
    assert "gripper-3f" not in [d.id for d in service.catalogue()]


def test_repair_may_add_a_library_device(tmp_path: Path) -> None:
    cell = tmp_path / "robot-only.yaml"
    cell.write_text(f"cell: robot-only\nlibraries: [{THREE_FINGER}]\ndevices:\n  - {BUILTIN / 'devices' / 'robot.ttl'}\n")
    k = service.knowledge((THREE_FINGER,), builtin=False)
    repairs = service.repair(THREE_FINGER / "tasks" / "squeeze-and-open.yaml", cell, service.catalogue(knowledge=k),
                             knowledge=k)
    assert any(r.added_devices == ("gripper-3f",) for r in repairs), repairs


def _copy_process(into: Path, name: str) -> Path:
    (into / "processes").mkdir(parents=True, exist_ok=True)
    for suffix in (".ttl", ".scxml"):
        shutil.copy(BUILTIN / "processes" / f"{name}{suffix}", into / "processes")
    return into / "processes" / f"{name}.ttl"


def test_the_same_process_id_in_two_libraries_names_both_files(tmp_path: Path) -> None:
    copy = _copy_process(tmp_path / "mine", "pick")
    with pytest.raises(DescriptionError) as caught:
        load_knowledge((builtin_library(), Library(tmp_path / "mine")))
    message = caught.value.location_message()
    assert message.startswith(f"{copy}:") and f"{BUILTIN / 'processes' / 'pick.ttl'}:" in message
    assert "process id 'pick' is defined twice" in message


def test_the_same_device_id_in_two_libraries_names_both_files(tmp_path: Path) -> None:
    (tmp_path / "mine" / "devices").mkdir(parents=True)
    for suffix in (".ttl", ".scxml"):
        shutil.copy(BUILTIN / "devices" / f"gripper{suffix}", tmp_path / "mine" / "devices")
    k = load_knowledge((builtin_library(), Library(tmp_path / "mine")))
    with pytest.raises(DescriptionError, match="device id 'gripper' is defined twice") as caught:
        _ = k.devices
    assert str(BUILTIN / "devices" / "gripper.ttl") in str(caught.value)


def test_validate_refuses_two_files_describing_the_same_iri(tmp_path: Path) -> None:
    copy = _copy_process(tmp_path / "mine", "pick")
    result = runner.invoke(app, ["validate", str(BUILTIN / "processes" / "pick.ttl"), str(copy)])
    assert result.exit_code == 1
    assert "is already described at" in result.stdout and str(copy) in result.stdout


def test_a_cell_file_lists_its_libraries_relative_to_itself(tmp_path: Path) -> None:
    shutil.copytree(THREE_FINGER, tmp_path / "lib")
    (tmp_path / "cells").mkdir()
    cell = tmp_path / "cells" / "cell.yaml"
    cell.write_text("cell: relative\nlibraries: [../lib]\ndevices:\n  - ../lib/devices/gripper-3f.ttl\n")
    assert service.capabilities(cell).commands() == ["close-gripper", "open-gripper"]


def test_a_library_ontology_is_classified_and_cached_by_content(tmp_path: Path) -> None:
    first = load_knowledge((builtin_library(), Library(THREE_FINGER)))
    again = load_knowledge((builtin_library(), Library(THREE_FINGER)))
    assert first.taxonomy.digest == again.taxonomy.digest != service.knowledge().taxonomy.digest


def test_repair_says_which_catalogue_device_could_serve_a_role_no_device_plays(tmp_path: Path) -> None:
    task = tmp_path / "squeeze.yaml"
    task.write_text("task: s\nsteps:\n  - command: squeeze\n")
    robot_only = tmp_path / "robot.yaml"
    robot_only.write_text(f"cell: robot-only\ndevices:\n  - {BUILTIN / 'devices' / 'robot.ttl'}\n")
    result = runner.invoke(app, ["--library", str(THREE_FINGER), "repair", str(task), "--cell", str(robot_only)])
    line = next(x for x in result.stdout.splitlines() if x.startswith("step 1, role 'gripper'"))
    assert "could play it: gripper, gripper-3f, magnetic-gripper, vacuum-gripper" in line


def test_repair_says_when_no_catalogue_device_could_serve(tmp_path: Path) -> None:
    task = tmp_path / "squeeze.yaml"
    task.write_text("task: s\nsteps:\n  - command: squeeze\n")
    gripper_only = tmp_path / "gripper.yaml"
    gripper_only.write_text(f"cell: gripper-only\ndevices:\n  - {THREE_FINGER / 'devices' / 'gripper-3f.ttl'}\n")
    result = runner.invoke(app, ["--no-builtin", "--library", str(THREE_FINGER), "repair", str(task), "--cell",
                                 str(gripper_only)])
    assert "step 1, role 'robot': no catalogue device (built-in or library) can play it" in result.stdout


def test_a_cell_names_library_devices_by_id(tmp_path: Path) -> None:
    cell = tmp_path / "by-id.yaml"
    cell.write_text(f"cell: by-id\nlibraries: [{THREE_FINGER}]\ndevices:\n  - robot\n  - gripper-3f\n")
    assert "pick" in service.capabilities(cell).commands()
    assert [d.id for d in service.cell(cell).devices] == ["robot", "gripper-3f"]
    assert runner.invoke(app, ["validate", str(cell)]).exit_code == 0


def test_an_unknown_device_id_in_a_cell_is_bad_input(tmp_path: Path) -> None:
    cell = tmp_path / "by-id.yaml"
    cell.write_text("cell: by-id\ndevices:\n  - robot\n  - robott\n")
    result = runner.invoke(app, ["capabilities", "--cell", str(cell)])
    assert result.exit_code == 2
    assert result.output.startswith(f"{cell}:4: device description robott not found")


def test_batch_takes_library_devices_processes_and_tasks(tmp_path: Path) -> None:
    configs = tmp_path / "configs.jsonl"
    configs.write_text('{"config": "3f", "devices": ["robot", "gripper-3f"]}\n'
                       '{"config": "robot-only", "devices": ["robot"]}\n')
    result = runner.invoke(app, ["--library", str(THREE_FINGER), "batch", str(configs), "--workers", "1", "--top", "5",
                                 "--task", str(THREE_FINGER / "tasks" / "squeeze-and-open.yaml")])
    assert result.exit_code == 0, result.output
    rows = {r["config"]: r for r in map(json.loads, result.stdout.splitlines())}
    assert "squeeze" in rows["3f"]["offered"] and rows["3f"]["plausible"] == ["squeeze-and-open"]
    assert ["gripper-3f"] in [o["add"] for o in rows["robot-only"]["purchase"]["options"]]


def test_an_inconsistent_extension_is_named(tmp_path: Path) -> None:
    (tmp_path / "bad" / "ontology").mkdir(parents=True)
    bad = tmp_path / "bad" / "ontology" / "bad.ttl"
    bad.write_text("@prefix pnp: <http://plugnproduce.org/ontology#> .\n@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
                   "<http://example.org/x> a pnp:Robot , pnp:Skill .\npnp:Device owl:disjointWith pnp:Skill .\n")
    result = runner.invoke(app, ["--library", str(tmp_path / "bad"), "vocab"])
    assert result.exit_code == 2
    assert result.output == f"error: the ontology is inconsistent (HermiT) with the extension(s) {bad}\n"


def test_the_reasoning_layer_takes_one_knowledge_with_the_processes_indexed_once() -> None:
    glue = Path(__file__).parents[1] / "data" / "libraries" / "glue-dispensing"
    k = service.knowledge((str(glue),))
    assert k.processes_by_id is k.processes_by_id and k.process("lay-bead") is k.processes_by_id["lay-bead"]
    with pytest.raises(KeyError):
        k.process("lay-beads")
    from plugnproduce import reasoning  # the layer itself, as an integration builds on it
    from plugnproduce.knowledge import Knowledge

    cell, task = service.cell(glue / "cells" / "glue-cell.yaml", k), service.task(glue / "tasks" / "glue.yaml")
    result = reasoning.check(task, cell, k)
    assert result.plausible and [s.command for s in result.steps] == [s.command for s in task.steps]
    own = Knowledge((), k.taxonomy, k.processes)  # processes of one's own, no library: no catalogue
    assert reasoning.check(task, cell, own) == result and own.devices == ()
    assert "lay-bead" in reasoning.capabilities(cell, own).commands()
