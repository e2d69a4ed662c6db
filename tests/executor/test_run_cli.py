"""``pnp run --sim`` and ``pnp report`` as a user runs them."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

from plugnproduce import service
from tests.lines import WAIT
from tests.processes import stop

TASKS = service.builtin("tasks")


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=120)


def test_run_on_the_simulated_cell_then_report(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASKS / "bin-picking.yaml"), "--sim", "--journal", str(journal))
    assert result.returncode == 0, result.stderr
    assert "step 1: bin-pick" in result.stdout and "→ gripper: Close" in result.stdout
    assert result.stdout.rstrip().splitlines()[-1] == f"succeeded; journal {journal}"
    shown = pnp("report", str(journal))
    assert shown.returncode == 0
    assert "end: succeeded" in shown.stdout and shown.stdout.rstrip().endswith("status: succeeded")


def test_a_failed_run_exits_1_with_the_fault(tmp_path: Path) -> None:
    result = pnp("run", str(TASKS / "bin-picking.yaml"), "--sim", "--json", "--faults", "gripper:error-response",
                 "--journal", str(tmp_path / "run.jsonl"))
    assert result.returncode == 1
    report = json.loads(result.stdout)
    assert report["outcome"] == "failed" and report["fault"]["device"] == "gripper"


def test_an_implausible_task_is_not_run() -> None:
    result = pnp("run", str(TASKS / "bin-picking-invalid.yaml"), "--sim")
    assert result.returncode == 1
    assert "not plausible" in result.stderr and "step 2 (bin-pick)" in result.stderr


def test_bad_fault_spec_is_bad_input() -> None:
    result = pnp("run", str(TASKS / "bin-picking.yaml"), "--sim", "--faults", "gripper:explode")
    assert result.returncode == 2
    assert "unknown kind 'explode'" in result.stderr and "Traceback" not in result.stderr


def test_sigterm_stops_the_run_safely_and_the_journal_ends(tmp_path: Path) -> None:
    """A supervisor's SIGTERM mid-run: no traceback, exit 1, and the journal ends with the stop."""
    journal = tmp_path / "run.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "plugnproduce", "run", str(TASKS / "bin-picking.yaml"), "--sim",
                             "--journal", str(journal)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        for line in proc.stdout:  # wait for the first command to reach a device
            if line.startswith("→"):
                break
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=WAIT)
    finally:
        stop(proc, signal.SIGKILL)  # no effect once it has exited
    assert proc.returncode == 1, err
    assert "Traceback" not in err
    shown = service.report(journal)
    assert shown.status == "stopped"
    assert [r["request"] for r in shown.of_kind("stop") if r["device"] == "robot"] == ["Halt"]
    report = pnp("report", str(journal))
    assert report.stdout.rstrip().endswith("status: stopped; stopped safely")


def test_report_tells_a_crash_from_a_safe_stop(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    assert pnp("run", str(TASKS / "bin-picking.yaml"), "--sim", "--journal", str(journal)).returncode == 0
    crashed = tmp_path / "crashed.jsonl"
    crashed.write_text("".join(journal.read_text().splitlines(keepends=True)[:5]))  # the controller died mid-run
    shown = pnp("report", str(crashed))
    assert shown.returncode == 0
    assert shown.stdout.rstrip().splitlines()[-1] == ("status: crashed; no end record: no safe stop is known to "
                                                      "have been sent")


def test_two_runs_never_share_a_journal(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    journal.write_text("")
    result = pnp("run", str(TASKS / "bin-picking.yaml"), "--sim", "--journal", str(journal))
    assert result.returncode == 2
    assert "already exists" in result.stderr and "Traceback" not in result.stderr
    assert journal.read_text() == ""


def test_a_journal_that_is_not_text_is_reported_at_its_line(tmp_path: Path) -> None:
    journal = tmp_path / "run.jsonl"
    journal.write_bytes(b'{"kind": "start", "seq": 1}\n\xff\xfe\n')
    result = pnp("report", str(journal))
    assert result.returncode == 2
    assert f"{journal}:2: not a journal: not UTF-8 text" in result.stderr
    assert "Traceback" not in result.stderr
