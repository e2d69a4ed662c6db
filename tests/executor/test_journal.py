"""The run journal: durable, append-only, and a crash is told apart from a finished run."""

from __future__ import annotations

import json
import os
import threading
from pathlib import Path

import pytest

from plugnproduce.errors import DescriptionError
from plugnproduce.executor.journal import Journal, describe, read_journal


def test_records_are_on_disk_as_soon_as_written(tmp_path: Path) -> None:
    path = tmp_path / "run.jsonl"
    journal = Journal(path)
    journal.write("start", task="t", cell="c")
    journal.write("command", device="gripper", command="xirp.request.Close", params={"GripForce": 40})
    # Not closed: a reader (or a crash) sees both records already.
    run = read_journal(path)
    assert [r["kind"] for r in run.records] == ["start", "command"]
    assert run.status == "crashed"
    journal.close()


def test_finished_run_has_its_outcome(tmp_path: Path) -> None:
    path = tmp_path / "run.jsonl"
    with Journal(path) as journal:
        journal.write("start", task="t", cell="c")
        journal.write("end", outcome="succeeded")
    run = read_journal(path)
    assert run.status == "succeeded"
    assert [r["seq"] for r in run.records] == [1, 2]


def test_torn_last_line_is_ignored_but_damage_elsewhere_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "run.jsonl"
    good = json.dumps({"seq": 1, "t": 0, "kind": "start"})
    path.write_text(good + "\n" + '{"seq": 2, "t": 0, "ki')
    assert read_journal(path).status == "crashed"
    path.write_text('{"seq": 1, "t"\n' + good + "\n")
    with pytest.raises(DescriptionError) as err:
        read_journal(path)
    assert err.value.line == 1


def test_unknown_kind_is_refused(tmp_path: Path) -> None:
    with Journal(tmp_path / "run.jsonl") as journal, pytest.raises(ValueError, match="unknown journal record kind"):
        journal.write("gossip")


def test_describe_reads_like_a_log() -> None:
    assert describe({"kind": "command", "device": "gripper", "command": "xirp.request.Close", "params": None}) == (
        "→ gripper: xirp.request.Close"
    )
    assert describe({"kind": "end", "outcome": "failed", "reason": "timeout"}) == "end: failed (timeout)"
    assert describe({"kind": "start", "task": "t", "cell": "c", "speed": 0.25}) == (
        "start task t on cell c (simulated devices, speed 0.25)")
    assert describe({"kind": "start", "task": "t", "cell": "c"}) == "start task t on cell c"  # real devices


def test_what_the_run_observed_is_flushed_at_once_and_fsynced_before_the_next_command(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path, synced, real_fsync, done = tmp_path / "j.jsonl", list[int](), os.fsync, threading.Semaphore(0)

    def counting(fd: int) -> None:  # how many records were on disk at each fsync
        synced.append(len(read_journal(path).records))
        real_fsync(fd)
        done.release()

    monkeypatch.setattr("os.fsync", counting)
    with Journal(path) as journal:
        journal.write("start", task="t")
        journal.write("step", step=1)
        journal.write("state", step=1, device="robot", state="moving")
        assert [r["kind"] for r in read_journal(path).records] == ["start", "step", "state"]  # another reader sees them
        journal.write("command", step=1, device="robot", command="MoveTo", params={})
        assert done.acquire(timeout=60) and done.acquire(timeout=60)  # the command's fsync runs in a thread
        journal.write("event", step=1, device="robot", event="motion_done", params={})
    assert synced == [1, 4, 5]  # start; the command with what came before it; the event when the journal closes


def test_a_command_goes_out_while_its_record_is_fsynced_and_the_next_command_waits_for_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A slow disk (an fsync of milliseconds, more on an SD card) does not add its time to every command."""
    path, real_fsync, release, synced = tmp_path / "j.jsonl", os.fsync, threading.Event(), list[int]()

    def slow(fd: int) -> None:
        assert release.wait(60), "the fsync was never let through"
        real_fsync(fd)
        synced.append(len(read_journal(path).records))

    with Journal(path) as journal:
        journal.write("start", task="t")
        monkeypatch.setattr("os.fsync", slow)
        journal.write("command", step=1, device="robot", command="MoveTo", params={})
        assert synced == []  # write returned while the record is being made durable: the command can go out
        assert [r["kind"] for r in read_journal(path).records] == ["start", "command"]  # flushed to the system
        journal.write("state", step=1, device="robot", state="moving")  # what the run observes does not wait
        threading.Timer(0.05, release.set).start()  # the disk is done later, while the device works
        journal.write("command", step=1, device="gripper", command="Close", params={})
        assert synced[0] >= 2  # the next command waited for the first one's fsync
    assert len(synced) == 2
