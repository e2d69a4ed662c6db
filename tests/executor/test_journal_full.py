"""A journal that cannot be written stops the run safely, said in one line: never a run going on unjournalled."""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.executor.journal import Journal, JournalWriteError, read_journal

TASK = str(service.builtin("tasks", "pick-and-place.yaml"))
LIMIT = 1500
"""Bytes the run's files may grow to: the journal fills up a few records into the run (a full disk, in effect)."""


def _small_files() -> None:
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))  # Python ignores SIGXFSZ: a write gets EFBIG


def test_issue_24_a_journal_that_fills_up_triggers_the_safe_stop_and_one_line_on_stderr(tmp_path: Path) -> None:
    # a 12 KB tmpfs: exit 2 with two asyncio tracebacks, the devices left as they were
    journal = tmp_path / "run.jsonl"
    done = subprocess.run([sys.executable, "-m", "plugnproduce", "run", TASK, "--sim", "--journal", str(journal)],
                          capture_output=True, text=True, timeout=300, preexec_fn=_small_files)
    assert done.returncode == 1, done.stdout + done.stderr
    assert done.stderr.splitlines() == [
        f"error: journal {journal} cannot be written: File too large; the run was stopped safely, its journal "
        "ends before the stop"], done.stderr
    assert "fault: journal at " in done.stdout
    stops = [line for line in done.stdout.splitlines() if line.startswith("stop ")]
    assert {line.split()[1].rstrip(":") for line in stops} == {"robot", "gripper", "sensor3d", "binpicking-pc"}
    kept = read_journal(journal)  # what was written before the disk filled, without its torn line
    assert kept.start["task"] == "pick-and-place" and kept.end is None


def test_a_failed_write_is_raised_with_its_record_and_nothing_more_is_written(tmp_path: Path,
                                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    with Journal(tmp_path / "j.jsonl") as journal:
        journal.write("start", task="t")
        real_fsync = __import__("os").fsync

        def failing(fd: int) -> None:
            raise OSError(28, "No space left on device")

        monkeypatch.setattr("os.fsync", failing)
        with pytest.raises(JournalWriteError, match="cannot be written: No space left on device") as caught:
            journal.write("fault", step=1)
        assert caught.value.record["kind"] == "fault"
        monkeypatch.setattr("os.fsync", real_fsync)
        with pytest.raises(JournalWriteError):
            journal.write("end", outcome="failed")  # a torn line stays the last one
    assert [r["kind"] for r in read_journal(tmp_path / "j.jsonl").records] == ["start", "fault"]


def test_a_command_s_failed_fsync_fails_the_next_write_and_nothing_more_is_written(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The command's record is fsynced while the command goes out; the next command, fault, stop or end
    waits for it, and its failure is theirs: the run then stops safely."""
    with Journal(tmp_path / "j.jsonl") as journal:
        journal.write("start", task="t")

        def failing(fd: int) -> None:
            raise OSError(5, "Input/output error")

        monkeypatch.setattr("os.fsync", failing)
        journal.write("command", step=1)
        with pytest.raises(JournalWriteError, match="cannot be written: Input/output error") as caught:
            journal.write("command", step=2)
        assert caught.value.record["kind"] == "command" and caught.value.record["step"] == 2
        with pytest.raises(JournalWriteError):
            journal.write("end", outcome="failed")
    assert [r.get("step") for r in read_journal(tmp_path / "j.jsonl").records] == [None, 1]
