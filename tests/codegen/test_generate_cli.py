"""``pnp generate``: the charts of a task written to a folder, or nothing for an implausible task."""

from __future__ import annotations

import json
from pathlib import Path

from lxml import etree
from typer.testing import CliRunner

from plugnproduce.cli import app
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import PNP_NS, parse_chart, schema_problems, write_chart

runner = CliRunner()
TASKS = descriptions_path() / "tasks"
CELL = str(descriptions_path() / "cells" / "bin-picking.yaml")
SCXML = "{http://www.w3.org/2005/07/scxml}"


def generate(out: Path, task: str = "bin-picking.yaml", *extra: str):
    return runner.invoke(app, ["generate", str(TASKS / task), "--cell", CELL, "-o", str(out), *extra])


def test_writes_schema_valid_charts_and_says_what(tmp_path: Path) -> None:
    result = generate(tmp_path)
    assert result.exit_code == 0, result.output
    files = sorted(tmp_path.iterdir())
    names = [f.name for f in files]
    assert "bin-picking.task.scxml" in names and "bin-picking.closed-world.scxml" in names
    # repeat 3 x (bin-pick, place): steps 4-6 run the charts of steps 2-3 (the robot starts at the place pose)
    assert [n for n in names if n.startswith("step")] == ["step01-bin-pick.scxml", "step02-place.scxml",
                                                          "step03-bin-pick.scxml"]
    for f in files:
        assert f"wrote {f}" in result.output
        assert schema_problems(f.read_bytes(), str(f)) == [], f.name


def test_gripper_region_sends_open_and_waits_for_the_event(tmp_path: Path) -> None:
    generate(tmp_path)
    task = etree.parse(str(tmp_path / "bin-picking.task.scxml"))
    gripper = [r for r in task.iter(f"{SCXML}state") if r.get(f"{{{PNP_NS}}}device") == "gripper" and r.get(f"{{{PNP_NS}}}role")]
    sends = [s.get("event") for r in gripper for s in r.iter(f"{SCXML}send") if s.get("type") == "xirp"]
    waits = [t.get("event") for r in gripper for t in r.iter(f"{SCXML}transition") if t.get("event")]
    assert "xirp.request.Open" in sends and "xirp.request.Close" in sends
    assert "gripper.xirp.event.gripper_closed" in waits


def test_output_is_byte_identical_across_runs(tmp_path: Path) -> None:
    assert generate(tmp_path / "a").exit_code == 0
    assert generate(tmp_path / "b").exit_code == 0
    names = sorted(f.name for f in (tmp_path / "a").iterdir())
    assert names == sorted(f.name for f in (tmp_path / "b").iterdir())
    assert "bin-picking.task.scxml" in names and "bin-picking.closed-world.scxml" in names
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name


def test_generated_charts_round_trip_through_the_reader_and_writer(tmp_path: Path) -> None:
    assert generate(tmp_path).exit_code == 0
    assert len(list(tmp_path.iterdir())) >= 3
    for f in tmp_path.iterdir():
        once = write_chart(parse_chart(f.read_bytes(), f))
        assert write_chart(parse_chart(once, f)) == once, f.name


def test_per_device_writes_one_program_per_used_device(tmp_path: Path) -> None:
    result = generate(tmp_path, "bin-picking.yaml", "--per-device", "--json")
    assert result.exit_code == 0, result.output
    programs = {Path(w["file"]).name for w in json.loads(result.output)["written"] if w["kind"] == "device-program"}
    assert programs == {f"bin-picking.{d}.program.scxml" for d in ("binpicking-pc", "gripper", "robot", "sensor3d")}


def test_implausible_task_is_refused_with_the_reason_and_nothing_is_written(tmp_path: Path) -> None:
    result = generate(tmp_path / "out", "bin-picking-invalid.yaml")
    assert result.exit_code == 1
    assert "bin-picking-invalid.yaml:8: step 2 (bin-pick): device 'gripper'" in result.output
    assert not (tmp_path / "out").exists()


def test_missing_task_file_is_bad_input(tmp_path: Path) -> None:
    result = runner.invoke(app, ["generate", str(tmp_path / "none.yaml"), "--cell", CELL, "-o", str(tmp_path)])
    assert result.exit_code == 2
    assert "none.yaml" in result.output and "Traceback" not in result.output
