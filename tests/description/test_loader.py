"""Reading every built-in description into the model, and the task format's round trip."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.description.loader import (
    load_cell,
    load_device,
    load_process,
    load_task,
    parse_task,
    task_to_yaml,
)
from plugnproduce.description.model import Command
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.resources import descriptions_path

D = descriptions_path()
P = "http://plugnproduce.org/ontology#"


@pytest.mark.parametrize("ttl", sorted((D / "devices").glob("*.ttl")), ids=lambda p: p.stem)
def test_every_device_loads_with_reasoned_skills(ttl: Path, taxonomy: Taxonomy) -> None:
    device = load_device(ttl, taxonomy)
    assert device.id == ttl.stem
    assert device.skills, "every catalogue device can do something"
    assert device.initial in {s.id for s in device.states}
    assert all(t.request is None or t.request.protocol == device.protocol for t in device.transitions)


@pytest.mark.parametrize("ttl", sorted((D / "processes").glob("*.ttl")), ids=lambda p: p.stem)
def test_every_process_loads_with_its_regions(ttl: Path, taxonomy: Taxonomy) -> None:
    process = load_process(ttl)
    assert process.id == ttl.stem
    for role in process.roles:
        assert taxonomy.is_kind(role.required_skill, "Skill")
        assert len(role.region) >= 2
    for p in process.parameters:
        assert p.role in {r.name for r in process.roles}


def test_gripper_is_the_papers_figure_2(taxonomy: Taxonomy) -> None:
    gripper = load_device(D / "devices" / "gripper.ttl", taxonomy)
    assert {s.id for s in gripper.states} == {"open", "closed", "opening", "closing", "configuring"}
    assert P + "CanGrip" in gripper.skills and P + "CanParallelGrip" in gripper.skills
    close = next(t for t in gripper.transitions if t.event == "xirp.request.Close")
    assert close.request == Command("xirp", "request", "Close")
    to_closed = next(t for t in gripper.transitions if t.target == "closed")
    assert to_closed.sends == (Command("xirp", "event", "gripper_closed"),)
    set_angle = next(t for t in gripper.transitions if t.event == "xirp.request.SetAngle")
    assert set_angle.target == "configuring" and set_angle.accepts == (P + "OpeningAngle",)


def test_bin_picking_cell_has_the_papers_four_devices(taxonomy: Taxonomy) -> None:
    cell = load_cell(D / "cells" / "bin-picking.yaml", taxonomy)
    assert sorted(d.id for d in cell.devices) == ["binpicking-pc", "gripper", "robot", "sensor3d"]
    assert {d.protocol for d in cell.devices} == {"xirp", "upnp"}
    assert sorted(d.id for d in cell.without("gripper").devices) == ["binpicking-pc", "robot", "sensor3d"]


def test_task_repeat_expands_and_keeps_lines() -> None:
    task = load_task(D / "tasks" / "bin-picking.yaml")
    assert task.repeat == 3
    assert [s.command for s in task.steps] == ["bin-pick", "place"] * 3
    assert [s.index for s in task.steps] == [1, 2, 3, 4, 5, 6]
    assert task.steps[0].line == task.steps[2].line == 6
    assert task.steps[0].params["grip_force"] == 45
    assert task.steps[1].params["place_pose"] == [0.6, -0.2, 0.1, 0, 180, 0]


@pytest.mark.parametrize("name", sorted(p.name for p in (D / "tasks").glob("*.yaml")))
def test_task_yaml_round_trip(tmp_path: Path, name: str) -> None:
    task = load_task(D / "tasks" / name)
    again = tmp_path / name
    again.write_text(task_to_yaml(task))
    back = load_task(again)
    assert [(s.name, s.command, s.bind, s.params) for s in back.steps] == \
        [(s.name, s.command, s.bind, s.params) for s in task.steps]
    assert (back.name, back.description, back.repeat) == (task.name, task.description, task.repeat)
    assert [(lp.entry, lp.first, lp.last, lp.until, lp.max) for lp in back.loops] == \
        [(lp.entry, lp.first, lp.last, lp.until, lp.max) for lp in task.loops]


@pytest.mark.parametrize(
    ("text", "line", "needle"),
    [
        ("task: t\n", 1, "needs 'task'"),
        ("task: t\nsteps:\n  - params: {a: 1}\n", 3, "needs 'command'"),
        ("task: t\nrepeat: 0\nsteps:\n  - command: pick\n", 2, "repeat must be"),
        ("task: t\nsteps:\n  - command: pick\n    colour: red\n", 4, "unknown key 'colour'"),
        ("task: t\ntask: u\nsteps: []\n", 2, "appears twice"),
        ("task: t\nrepeat: 1000\nsteps:\n" + "  - command: pick\n" * 11, 4,
         "11 steps repeated 1000 times make 11000; at most 10000 are accepted"),
        ("task: t\nsteps:\n  - loop:\n      steps:\n        - command: pick\n", 4,
         "a loop needs a way out: 'until: OUTCOME', 'max: N' or both"),
        ("task: t\nsteps:\n  - loop:\n      max: 2\n      steps:\n        - loop: {max: 2, steps: []}\n", 6,
         "a loop needs 'steps', a non-empty list"),
        ("task: t\nrepeat: 2\nsteps:\n  - loop: {max: 2, steps: [{command: pick}]}\n", 4,
         "a task with a loop cannot also repeat"),
        ("task: t\nsteps:\n  - command: pick\n    params:\n      pick_pose: {from: a}\n", 5,
         "a parameter taken from an earlier step reads {from: STEP, output: NAME}"),
        ("task: t\nsteps:\n  - name: a\n    command: pick\n  - name: a\n    command: place\n", 5,
         "step name 'a' appears twice"),
    ],
)
def test_bad_task_names_file_and_line(tmp_path: Path, text: str, line: int, needle: str) -> None:
    f = tmp_path / "t.yaml"
    f.write_text(text)
    with pytest.raises(DescriptionError) as err:
        load_task(f)
    assert (err.value.file, err.value.line) == (str(f), line)
    assert needle in err.value.message


def test_cell_with_missing_device_file(tmp_path: Path, taxonomy: Taxonomy) -> None:
    f = tmp_path / "c.yaml"
    f.write_text("cell: c\ndevices:\n  - nowhere.ttl\n")
    with pytest.raises(DescriptionError, match="nowhere.ttl not found") as err:
        load_cell(f, taxonomy)
    assert err.value.line == 3


@pytest.mark.parametrize("name", sorted(p.name for p in (D / "tasks").glob("*.yaml")))
def test_a_task_read_from_bytes_is_the_task_read_from_its_file(name: str) -> None:
    path = D / "tasks" / name
    from_file, from_bytes = load_task(path), parse_task(path.read_bytes(), "upload.yaml")
    assert from_bytes.file == "upload.yaml"
    assert from_bytes.steps == from_file.steps and from_bytes.repeat == from_file.repeat
    assert [s.param_lines for s in from_bytes.steps] == [s.param_lines for s in from_file.steps]


@pytest.mark.parametrize("block", [False, True])
def test_the_task_writer_writes_one_round_and_reads_back_the_same_steps(block: bool) -> None:
    task = load_task(D / "tasks" / "bin-picking.yaml")
    text = task_to_yaml(task, block=block)
    assert text.count("command:") == len(task.one_round()) == 2
    back = parse_task(text.encode(), "written.yaml")
    assert [(s.index, s.command, s.bind, s.params) for s in back.steps] == \
        [(s.index, s.command, s.bind, s.params) for s in task.steps]
    assert back.repeat == task.repeat == 3


def test_a_block_written_task_puts_each_parameter_on_its_own_line() -> None:
    task = load_task(D / "tasks" / "bin-picking.yaml")
    back = parse_task(task_to_yaml(task, block=True).encode(), "written.yaml")
    lines = [line for s in back.one_round() for line in s.param_lines.values()]
    assert len(lines) == len(set(lines)) == sum(len(s.params) for s in task.one_round())


def test_bad_task_text_names_its_source_and_line() -> None:
    with pytest.raises(DescriptionError) as err:
        parse_task(b"task: t\nsteps:\n  - command: pick\n    colour: red\n", "mine.yaml")
    assert (err.value.file, err.value.line) == ("mine.yaml", 4)
