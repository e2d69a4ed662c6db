"""A device that takes its poses in another pose unit than the process gives them (tests/data/libraries/mm-arm:
an arm whose TargetPose is in "mm deg", the move-to process's target_pose in "m deg"): each pose is converted
per component before it leaves the controller, and its reach is judged in the device's unit."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "mm-arm"
CELL = LIBRARY / "cells" / "mm-arm.yaml"


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=180)


def test_a_literal_and_a_default_pose_go_out_in_millimetres(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(LIBRARY / "tasks" / "move-near.yaml"), "--cell", str(CELL), "--sim",
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    poses = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r.get("device") == "mm-arm"]
    assert poses == [[600.0, 0.0, 0.0, 0.0, 180.0, 0.0], [300.0, 0.0, 400.0, 0.0, 180.0, 0.0]]


def test_the_generated_chart_sends_millimetres(tmp_path: Path) -> None:
    out = tmp_path / "gen"
    result = pnp("generate", str(LIBRARY / "tasks" / "move-near.yaml"), "--cell", str(CELL), "-o", str(out))
    assert result.returncode == 0, result.stderr
    text = "".join(p.read_text() for p in sorted(out.glob("*.scxml")))
    assert 'expr="[600, 0, 0, 0, 180, 0]"' in text
    assert "[0.6, 0, 0" not in text


def test_a_pose_within_the_reach_in_millimetres_is_plausible() -> None:
    result = pnp("check", str(LIBRARY / "tasks" / "move-near.yaml"), "--cell", str(CELL))
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_pose_two_metres_away_is_beyond_a_reach_of_1450_mm() -> None:
    task = LIBRARY / "tasks" / "move-far.yaml"
    result = pnp("check", str(task), "--cell", str(CELL))
    assert result.returncode == 1, result.stdout + result.stderr
    assert "1450 mm" in result.stdout and "2000 mm" in result.stdout
    assert f"{task.name}:5" in result.stdout


LOCALIZING = LIBRARY / "cells" / "mm-arm-localizing.yaml"
TO_PART = LIBRARY / "tasks" / "move-to-part.yaml"


def test_a_pose_from_another_step_is_converted_at_run_time(tmp_path: Path) -> None:
    """The localizer reports the part's pose in "m deg"; the arm gets it in millimetres."""
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TO_PART), "--cell", str(LOCALIZING), "--sim", "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    (reported,) = [r["produced"] for r in records if r["kind"] == "value" and "produced" in r]
    (sent,) = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r.get("device") == "mm-arm"]
    assert sent == pytest.approx([v * 1000 for v in reported[:3]] + list(reported[3:]))


def test_the_check_proves_a_linked_pose_within_the_reach_in_the_devices_unit() -> None:
    result = pnp("check", str(TO_PART), "--cell", str(LOCALIZING))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "binpicking-pc reports part_pose within 1.2 m of the base; mm-arm reaches 1450 mm" in result.stdout


def test_a_reach_of_1000_mm_does_not_prove_a_pose_reported_within_1_2_m(tmp_path: Path) -> None:
    library = Path(shutil.copytree(LIBRARY, tmp_path / "mm-arm"))
    ttl = library / "devices" / "mm-arm.ttl"
    ttl.write_text(ttl.read_text().replace("pnp:maxReach 1450", "pnp:maxReach 1000"))
    cell = library / "cells" / "mm-arm-localizing.yaml"
    cell.write_text(cell.read_text().replace("../../../../../descriptions", str(LIBRARY.parents[3] / "descriptions")))
    result = pnp("check", str(library / "tasks" / "move-to-part.yaml"), "--cell", str(cell))
    assert "within 1.2 m of the base, and mm-arm reaches only 1000 mm" in result.stdout, result.stdout + result.stderr


def test_the_library_is_valid() -> None:
    result = pnp("validate", *(str(p) for p in sorted(LIBRARY.glob("*/*")) if p.suffix in (".ttl", ".yaml")))
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize("unit", ["mm kg", "mm", "deg mm", "mm deg s", "mm degC"])
def test_a_device_argument_in_no_pose_unit_is_one_line_at_its_place(tmp_path: Path, unit: str) -> None:
    """Bad input to check (exit 2), a finding of validate (exit 1) as an unknown unit is; both at its line."""
    library = Path(shutil.copytree(LIBRARY, tmp_path / "mm-arm"))
    ttl = library / "devices" / "mm-arm.ttl"
    ttl.write_text(ttl.read_text().replace('pnp:unit "mm deg"', f'pnp:unit "{unit}"'))
    for command, code in ((("check", str(library / "tasks" / "move-near.yaml"), "--cell",
                            str(library / "cells" / "mm-arm.yaml")), 2), (("validate", str(ttl)), 1)):
        result = pnp(*command)
        assert result.returncode == code, result.stdout + result.stderr
        (line,) = (result.stdout + result.stderr).splitlines()
        assert line.startswith(f"{ttl}:16: ") and f"'{unit}' is no pose unit" in line, line


def test_a_process_parameter_in_no_pose_unit_is_refused_at_its_line(tmp_path: Path) -> None:
    from plugnproduce.description.loader import load_process
    from plugnproduce.errors import DescriptionError

    builtin = LIBRARY.parents[3] / "descriptions" / "processes"
    for name in ("move-to.ttl", "move-to.scxml"):
        shutil.copy(builtin / name, tmp_path / name)
    ttl = tmp_path / "move-to.ttl"
    ttl.write_text(ttl.read_text().replace('pnp:unit "m deg"', 'pnp:unit "m kg"'))
    with pytest.raises(DescriptionError) as raised:
        load_process(ttl)
    assert str(raised.value).startswith(f"{ttl}:15: ") and "'m kg' is no pose unit" in str(raised.value)


def test_poses_that_differ_between_steps_sharing_a_chart_go_out_in_millimetres(tmp_path: Path) -> None:
    """The second and third move share one chart and read their poses at run time, in "m deg"."""
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(LIBRARY / "tasks" / "move-three.yaml"), "--cell", str(CELL), "--sim",
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout + result.stderr
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    poses = [r["params"]["TargetPose"] for r in records if r["kind"] == "command" and r.get("device") == "mm-arm"]
    assert poses == [[600, 0, 0, 0, 180, 0], [500, 100, 200, 0, 180, 0], [400, -100, 300, 0, 90, 0]]
