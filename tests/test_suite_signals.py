"""The suite's processes stop on Ctrl-C however the suite was started (tests/conftest.py)."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

from tests.lines import WAIT

CHILD = """import signal, subprocess, sys

def test_a_started_process_hears_ctrl_c():
    child = "import signal, sys; sys.exit(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)"
    assert subprocess.run([sys.executable, "-c", child]).returncode == 0
"""


def test_a_suite_started_in_the_background_still_lets_its_processes_hear_ctrl_c(tmp_path: Path) -> None:
    """A shell starts a background job (``python -m pytest &``) with SIGINT ignored; the processes the tests start
    must still stop on the SIGINT a test sends them (else `pnp sim up` outlives its test and is killed)."""
    (tmp_path / "test_child.py").write_text(CHILD, encoding="utf-8")
    root = Path(__file__).resolve().parent.parent
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider", "-p", "tests.conftest",
         "--rootdir", str(tmp_path), str(tmp_path / "test_child.py")],
        cwd=root, capture_output=True, text=True, timeout=WAIT,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    assert run.returncode == 0, run.stdout + run.stderr
