"""Progress of long commands: on a terminal's stderr only, nothing extra when piped or with ``--json``."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
import threading
from pathlib import Path

from rich.console import Console

from plugnproduce import service
from plugnproduce.cli.console.progress import Phases
from tests.lines import WAIT
from tests.processes import stop

TASK = str(service.builtin("tasks", "bin-picking.yaml"))
ESCAPES = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def plain(terminal: str) -> list[str]:
    """The lines a terminal shows, without colours and cursor moves."""
    return [line.strip() for line in ESCAPES.sub("", terminal).replace("\r", "\n").splitlines()]


def run_with_terminal_stderr(*args: str) -> tuple[int, str, str]:
    """Run ``pnp ARGS`` with stderr on a pseudo-terminal and stdout a pipe: exit code, stdout, terminal text."""
    master, slave = os.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "plugnproduce", *args], stdout=subprocess.PIPE,
                            stderr=slave, stdin=subprocess.DEVNULL, text=True)
    os.close(slave)
    seen: list[bytes] = []

    def read() -> None:
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the child has gone and the terminal is closed
                return
            if not chunk:
                return
            seen.append(chunk)

    reader = threading.Thread(target=read)
    reader.start()
    try:
        out, _ = proc.communicate(timeout=120)
    finally:
        stop(proc)  # no effect once it has exited
    reader.join(timeout=WAIT)
    os.close(master)
    return proc.returncode, out, "\n".join(plain(b"".join(seen).decode("utf-8", "replace")))


def test_run_on_a_terminal_says_what_it_is_doing(tmp_path: Path) -> None:
    code, out, terminal = run_with_terminal_stderr("run", TASK, "--sim", "--journal", str(tmp_path / "run.jsonl"))
    assert code == 0, terminal
    for phase in ("starting 4 simulated device(s) on loopback", "discovering devices: robot",
                  "asking each device its state; checking the task from there", "generating the charts of 6 step(s)",
                  "running"):
        assert f"✓ {phase}" in terminal, phase
    assert "✓" not in out and out.startswith("start task bin-picking")


def test_run_with_json_on_a_terminal_shows_no_progress(tmp_path: Path) -> None:
    code, out, terminal = run_with_terminal_stderr("run", TASK, "--sim", "--json",
                                                   "--journal", str(tmp_path / "run.jsonl"))
    assert code == 0 and terminal.strip() == "" and out.startswith("{")


def test_run_piped_shows_no_progress(tmp_path: Path) -> None:
    result = subprocess.run([sys.executable, "-m", "plugnproduce", "run", TASK, "--sim",
                             "--journal", str(tmp_path / "run.jsonl")], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stderr == ""


def test_batch_piped_shows_no_progress() -> None:
    result = subprocess.run([sys.executable, "-m", "plugnproduce", "batch", "--generate", "3", "--workers", "1"],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stderr == "" and len(result.stdout.splitlines()) == 3


def test_batch_on_a_terminal_shows_its_progress() -> None:
    code, out, terminal = run_with_terminal_stderr("batch", "--generate", "3", "--workers", "1")
    assert code == 0 and len(out.splitlines()) == 3
    assert "batch" in terminal and "/3" in terminal


def test_validate_on_a_terminal_says_what_it_is_doing() -> None:
    code, out, terminal = run_with_terminal_stderr("validate", str(service.builtin("devices")))
    assert code == 0 and out.endswith("files valid\n")
    assert "✓ checking the SHACL shapes" in terminal and "description file(s)" in terminal


def test_validate_piped_shows_no_progress() -> None:
    result = subprocess.run([sys.executable, "-m", "plugnproduce", "validate", str(service.builtin("devices"))],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stderr == ""


def test_each_finished_phase_stays_as_a_line() -> None:
    buf = io.StringIO()
    with Phases(True, Console(file=buf, force_terminal=True, color_system=None, width=80)) as phases:
        phases("checking")
        phases("running")
        phases.update("step 1 (pick)")
        phases.close(last_done=True)
    lines = [line for line in plain(buf.getvalue()) if "✓" in line]
    assert [" ".join(line.split()[:2]) for line in lines] == ["✓ checking", "✓ running"]


def test_disabled_phases_print_nothing() -> None:
    buf = io.StringIO()
    with Phases(False, Console(file=buf, force_terminal=True)) as phases:
        phases("checking")
        phases.close(last_done=True)
    assert buf.getvalue() == ""


def run_on_a_terminal(*args: str) -> tuple[int, str]:
    """Run ``pnp ARGS`` with stdout and stderr on one pseudo-terminal, as a user sees it: exit code, raw text."""
    master, slave = os.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "plugnproduce", *args], stdout=slave, stderr=slave,
                            stdin=subprocess.DEVNULL)
    os.close(slave)
    seen: list[bytes] = []
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the child has gone and the terminal is closed
            break
        if not chunk:
            break
        seen.append(chunk)
    code = proc.wait(timeout=120)
    os.close(master)
    return code, b"".join(seen).decode("utf-8", "replace")


def test_the_spinner_is_cleared_before_each_event_line(tmp_path: Path) -> None:
    code, raw = run_on_a_terminal("run", TASK, "--sim", "--journal", str(tmp_path / "run.jsonl"))
    assert code == 0, raw[-2000:]
    lines = plain(raw)
    events = [line for line in lines if line.startswith(("→", "←", "step "))]
    assert len(events) > 20  # the run's lines are all there
    shared = [line for line in lines if "running" in line and any(m in line for m in ("→", "←", " is "))]
    assert shared == [], shared[:3]  # no event line runs on from the spinner's


def test_a_fault_run_says_what_was_sent_and_what_is_known_at_the_step_of_the_fault(tmp_path: Path) -> None:
    code, raw = run_on_a_terminal("run", TASK, "--sim", "--faults", "gripper:drop-response:Close",
                                  "--journal", str(tmp_path / "run.jsonl"))
    assert code == 1, raw[-2000:]
    lines = [line for line in plain(raw) if line and "running:" not in line]
    close = lines.index("→ gripper: Close {'GripForce': 45}")
    assert not any(line.startswith("→") for line in lines[close + 1:])  # nothing sent after the unanswered Close
    assert "gripper is closing" not in lines  # nobody confirmed that the gripper took the Close
    assert not any(line.startswith(("step 2", "step 3")) for line in lines)  # the run stays at step 1, the fault's
    assert lines[close + 1] == ("FAULT timeout: command Close: no answer within 2 s; it was sent, and whether gripper "
                                "carries it out is not known")
    assert "fault: timeout at step 1 (bin-pick), device gripper in state open, request Close: " \
           "command Close: no answer within 2 s" in raw
