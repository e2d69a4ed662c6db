"""A few fuzz crashers through ``pnp validate`` as a user runs it: exit 2 and one line each, no traceback."""

from __future__ import annotations

import subprocess
import sys

import pytest
from fuzzing import Workspace, check_message, seeds

GRIPPER = dict(seeds("turtle"))["devices/gripper.ttl"]
CASES = {
    "bad number": ("devices/gripper.ttl", GRIPPER.replace(b"pnp:cost 1800", b"pnp:cost " + b"9" * 400)),
    "turtle syntax": ("devices/gripper.ttl", GRIPPER.replace(b"pnp:cost 1800 .", b"pnp:cost 1800 ;;; ]")),
    "odd IRI": ("devices/gripper.ttl", GRIPPER.replace(b"dev:gripper a", b'<http://ex.org/a"b> a')),
    "NUL in YAML": ("tasks/bin-picking.yaml", b"task: t\nsteps:\n  - command: pi\x00ck\n"),
    "long device path": ("cells/assembly.yaml", b"cell: c\ndevices:\n  - " + b"x" * 5000 + b"\n"),
    "long namespace": ("devices/gripper.scxml", b'<scxml xmlns="http://www.w3.org/2005/07/scxml' + b"(" * 3000
                       + b'" version="1.0"/>'),
}

EXIT = {"bad number": 2, "turtle syntax": 2, "odd IRI": 0, "NUL in YAML": 2, "long device path": 1,
        "long namespace": 1}
"""0 valid, 1 invalid, 2 unreadable or hostile."""


@pytest.mark.parametrize("case", CASES, ids=list(CASES))
def test_validate_exits_with_one_line_per_problem(workspace: Workspace, case: str) -> None:
    relative, data = CASES[case]
    path = workspace.write(relative, data)
    proc = subprocess.run([sys.executable, "-m", "plugnproduce", "validate", str(path)], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == EXIT[case], proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr and proc.stderr.count("\n") <= 1, proc.stderr  # no library chatter
    lines = [line for line in proc.stdout.splitlines() if not line.endswith(" files valid")]
    assert all(line.startswith(str(path)) for line in lines), proc.stdout
    for line in lines:
        check_message(line, data)
