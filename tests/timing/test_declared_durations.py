"""Declared request durations are checked like any other part of a device description: at their line."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
OPEN = 'pnp:forRequest "Open" ; pnp:seconds 0.3'


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          timeout=120, env={**os.environ})


def library_with(tmp_path: Path, replacement: str) -> Path:
    library = tmp_path / "timed-cell"
    shutil.copytree(TIMED, library)
    gripper = library / "devices" / "tc-gripper.ttl"
    text = gripper.read_text()
    assert OPEN in text
    gripper.write_text(text.replace(OPEN, replacement))
    return library


def line_of(path: Path, needle: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if needle in line)


@pytest.mark.parametrize(("replacement", "message"), [
    ('pnp:forRequest "Opne" ; pnp:seconds 0.3', "duration of request Opne: no transition of the chart waits for "
                                                 "request Opne"),
    ('pnp:forRequest "Open" ; pnp:seconds -0.3', "pnp:seconds is one non-negative decimal number of seconds"),
    ('pnp:forRequest "Open" ; pnp:seconds 0.3 ; pnp:topSpeed 1.0 ; pnp:motionOf pnp:TargetPose',
     "a duration gives either pnp:seconds or a motion model (pnp:motionOf and pnp:topSpeed), not both"),
    ('pnp:forRequest "Open" ; pnp:topSpeed 1.0 ; pnp:motionOf pnp:TargetPose',
     "duration of request Open: the request does not take TargetPose (its pnp:accepts)"),
])
def test_a_wrong_duration_is_refused_at_its_line(tmp_path: Path, replacement: str, message: str) -> None:
    library = library_with(tmp_path, replacement)
    device = library / "devices" / "tc-gripper.ttl"
    result = pnp("validate", str(device))
    assert result.returncode == 1, result.stdout + result.stderr
    assert f"{device}:{line_of(device, 'tc-gripper-Open-time a')}:" in result.stdout
    assert message in result.stdout


def test_the_library_with_its_durations_validates() -> None:
    result = pnp("validate", str(TIMED))
    assert result.returncode == 0, result.stdout + result.stderr
