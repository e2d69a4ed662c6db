"""No process a test starts outlives the suite: the session fixture of tests/conftest.py finds and ends it."""

from __future__ import annotations

import subprocess
import sys
import uuid
from pathlib import Path

from tests.lines import WAIT
from tests.processes import ours, running_descendants, started

ROOT = Path(__file__).parents[1]
LEAKING = '''import subprocess, sys


def test_leaks_a_controller_process():
    subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)", "plugnproduce", "{marker}"])
'''


def test_a_running_child_is_listed_until_it_is_stopped() -> None:
    with started([sys.executable, "-c", "import time; time.sleep(600)", "plugnproduce"]) as proc:
        assert (proc.pid, f"{sys.executable} -c import time; time.sleep(600) plugnproduce") in running_descendants()
        assert ours(dict(running_descendants())[proc.pid])
    assert proc.pid not in dict(running_descendants())
    assert not ours("sleep 5") and ours("/usr/bin/python -m plugnproduce sim up cell.yaml")


def test_a_session_that_leaks_a_controller_process_fails_naming_it_and_the_process_is_ended(tmp_path: Path) -> None:
    marker = uuid.uuid4().hex
    (tmp_path / "test_leak.py").write_text(LEAKING.format(marker=marker), encoding="utf-8")
    session = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider",
                              "-c", str(ROOT / "pyproject.toml"), "--rootdir", str(ROOT), "-p", "tests.conftest",
                              str(tmp_path / "test_leak.py")], cwd=ROOT, capture_output=True, text=True, timeout=WAIT)
    assert session.returncode == 1, session.stdout
    assert "processes started by the tests outlived them" in session.stdout and marker in session.stdout
    leftover = subprocess.run(["ps", "-eo", "args"], capture_output=True, text=True, timeout=WAIT).stdout
    assert marker not in leftover
