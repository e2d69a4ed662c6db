"""The run journal: an append-only, fsynced JSON-lines file per run.

Every run writes one record per line: ``start`` (task, cell, chart digest, number of steps; with simulated devices,
their ``speed`` factor), then ``command`` (sent to a device), ``event`` (from a device or the chart), ``state`` (a
device region entered a state), ``step`` (a step began, with its role bindings), ``fault``, after a fault one
``stop`` per device (the safe-stop request sent, its answer, the state the device reports) and finally ``end``
(outcome). A run that resumes a stopped one (``pnp resume``) writes, right after its ``start``, ``stopped`` (the run
it resumes and how that one stopped), ``replan`` (the states the devices reported and the rest planned from them)
and ``continue`` (who confirmed it). A line is flushed to the operating system before the run goes on, so after a
crash of the controller the journal holds everything up to the crash, and a run without ``end`` is told apart from a
finished one. It is made durable on disk (fsynced) with ``start``, ``fault``, ``stop`` and ``end`` before the run
goes on, and with each ``command`` while the command goes out: its fsync runs in a thread, and the next command,
fault, stop or end waits until it is done (a failed fsync fails that next write). What the run observed in between
(``step``, ``state``, ``event``, ``value``, ``branch``) is fsynced with the next of these. One fsync per record held
up the event loop for milliseconds each, several times per command, while the devices' events waited; one fsync
before each command added as much to every command's time (2 to 13 ms measured on a busy disk, more on an SD card).
So a power failure of the controller may lose the record of the one command in flight; a crash of the controller
loses nothing.
Nothing is ever rewritten.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from plugnproduce.errors import DescriptionError, PlugNProduceError

KINDS = ("start", "stopped", "replan", "continue", "step", "command", "event", "value", "state", "branch", "fault",
         "stop", "end")
OBSERVED = frozenset({"step", "event", "value", "state", "branch"})
"""Kinds that record what the run saw, not what it did: flushed at once, fsynced with the next other record."""
OVERLAPPED = frozenset({"command"})
"""Kinds fsynced in a thread while the run goes on; the next record of another kind than OBSERVED waits for it."""


class JournalInUse(PlugNProduceError):
    """A run was given a journal file that already exists."""


class JournalWriteError(PlugNProduceError):
    """A record could not be written (a full disk, a file size limit, an I/O error); ``record`` is the record."""

    def __init__(self, message: str, record: dict[str, Any]) -> None:
        super().__init__(message)
        self.record = record


class Journal:
    """Appends records to a run's journal file, durably.

    Once a write fails, nothing more is written (a torn line stays the last one, as after a crash):
    each later :meth:`write` raises :class:`JournalWriteError` too, and the run stops safely.
    """

    def __init__(self, path: str | Path, clock: Any = time.time):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._clock = clock
        try:  # created here, never shared: two runs given one path must not interleave their records
            self._file: TextIO | None = self.path.open("x", encoding="utf-8")
        except FileExistsError as exc:
            raise JournalInUse(f"journal {self.path} already exists (another run's); give each run its own") from exc
        self._seq = 0
        self._unsynced = False
        self._syncer: ThreadPoolExecutor | None = None
        self._syncing: Future[None] | None = None
        self.failure: str | None = None
        """Why the journal could not be written (None: every record so far was)."""

    def write(self, kind: str, **data: Any) -> dict[str, Any]:
        """Append one record, make it durable (see the module's description: a record of what the run observed
        with the next one of what it did), and return it (:class:`JournalWriteError` if it cannot be)."""
        if kind not in KINDS:
            raise ValueError(f"unknown journal record kind {kind!r}")
        if self._file is None:
            raise ValueError(f"journal {self.path} is closed")
        self._seq += 1
        record = {"seq": self._seq, "t": round(self._clock(), 6), "kind": kind, **data}
        if self.failure is not None:
            raise JournalWriteError(self.failure, record)
        try:
            self._synced(wait=kind not in OBSERVED)
            self._file.write(json.dumps(record, sort_keys=True, default=str) + "\n")
            self._file.flush()
            if kind in OBSERVED:
                self._unsynced = True
            elif kind in OVERLAPPED:
                self._syncing = self._sync_thread().submit(os.fsync, self._file.fileno())
                self._unsynced = False
            else:
                os.fsync(self._file.fileno())
                self._unsynced = False
        except OSError as exc:
            self.failure = f"journal {self.path} cannot be written: {exc.strerror or exc}"
            raise JournalWriteError(self.failure, record) from exc
        return record

    def _sync_thread(self) -> ThreadPoolExecutor:
        if self._syncer is None:
            self._syncer = ThreadPoolExecutor(1, thread_name_prefix=f"journal {self.path.name}")
        return self._syncer

    def _synced(self, *, wait: bool) -> None:
        """Raise the OSError of the fsync running in the thread, once it is done (``wait``: wait for it)."""
        if self._syncing is not None and (wait or self._syncing.done()):
            syncing, self._syncing = self._syncing, None
            syncing.result()

    def close(self) -> None:
        """Close the file (records already written stay; what a failed write left unwritten is dropped)."""
        if self._file is not None:
            file, self._file = self._file, None
            try:
                if self._syncer is not None:
                    self._syncer.shutdown()  # the fsync in flight is done before the file closes
                self._synced(wait=True)
                if self._unsynced and self.failure is None:
                    os.fsync(file.fileno())
            except OSError:  # a failed fsync: what it did not make durable cannot be now either
                pass
            try:
                file.close()
            except OSError:  # the buffer of a failed write: it cannot be written now either
                pass

    def __enter__(self) -> Journal:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()


@dataclass
class RunRecord:
    """A run as its journal tells it."""

    path: Path
    records: list[dict[str, Any]] = field(default_factory=list)

    @property
    def start(self) -> dict[str, Any]:
        """The start record (empty if the journal has none)."""
        return next((r for r in self.records if r["kind"] == "start"), {})

    @property
    def end(self) -> dict[str, Any] | None:
        """The end record, or None if the run never finished (crashed or still running)."""
        return next((r for r in self.records if r["kind"] == "end"), None)

    @property
    def status(self) -> str:
        """``succeeded``, ``failed``, or ``crashed`` when the journal has no end."""
        if self.end is None:
            return "crashed"
        return str(self.end.get("outcome", "failed"))

    @property
    def safe_stop(self) -> str | None:
        """How the devices were left after a fault or a stop: ``stopped safely`` when every device that takes a
        safe-stop request accepted it, else which did not (or could not be asked); that no safe stop is known
        when the journal has no end record (a crash); None after a run that needed none."""
        if self.end is None:
            return "no end record: no safe stop is known to have been sent"
        stops = list(self.of_kind("stop"))
        if not stops:
            return None
        failed = [f"{r.get('device')} ({r.get('request') or 'state'}: {r.get('answer')})" for r in stops
                  if r.get("answer") not in (None, "accepted")]
        return "stopped safely" if not failed else f"safe stop incomplete: {', '.join(failed)}"

    def of_kind(self, kind: str) -> Iterator[dict[str, Any]]:
        """The records of one kind, in order."""
        return (r for r in self.records if r["kind"] == kind)


def read_journal(path: str | Path) -> RunRecord:
    """Read a journal; a torn last line (a crash mid-write) is ignored, any other bad line is an error."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise DescriptionError(f"cannot read journal: {exc.strerror or exc}", p) from exc
    try:
        lines = data.decode("utf-8").splitlines()
    except UnicodeDecodeError as exc:
        at = data.count(b"\n", 0, exc.start) + 1
        raise DescriptionError(f"not a journal: not UTF-8 text ({exc.reason})", p, at) from exc
    run = RunRecord(p)
    for number, line in enumerate(lines, start=1):
        try:
            record = json.loads(line)
        except json.JSONDecodeError as exc:
            if number == len(lines):
                break  # the write the crash interrupted
            raise DescriptionError(f"damaged journal line: {exc.msg}", p, number) from exc
        if not isinstance(record, dict) or record.get("kind") not in KINDS:
            raise DescriptionError("not a journal record", p, number)
        run.records.append(record)
    return run


def describe(record: dict[str, Any]) -> str:
    """One human line for a journal record."""
    kind = record["kind"]
    if kind == "start":
        speed = f" (simulated devices, speed {record['speed']:g})" if isinstance(record.get("speed"), int | float) \
            else ""
        return f"start task {record.get('task')} on cell {record.get('cell')}{speed}"
    if kind in ("stopped", "replan", "continue"):
        return _resumed(record)
    if kind == "step":
        return f"step {record.get('step')}: {record.get('command')}"
    if kind == "command":
        return f"→ {record.get('device')}: {record.get('command')} {record.get('params') or ''}".rstrip()
    if kind == "event" and record.get("ignored"):
        return f"← {record.get('device')}: {record.get('event')} (not acted on: {record.get('ignored')})"
    if kind == "event":
        return f"← {record.get('device') or 'chart'}: {record.get('event')}"
    if kind == "state":
        return f"  {record.get('device')} is {record.get('state')}"
    if kind == "value" and "produced" in record:
        return f"  value {record.get('value')} = {record.get('produced')} (from {record.get('device')})"
    if kind == "value":
        return (f"  value {record.get('value')} → {record.get('device')} as {record.get('parameter')}"
                f" = {record.get('used')}")
    if kind == "branch":
        taken = f"takes {record.get('path')}" if record.get("branch") else "goes on without a branch"
        return f"  step {record.get('step')} reported {record.get('outcome')}: the task {taken}"
    if kind == "fault":
        return f"FAULT {record.get('fault')}: {record.get('message')}"
    if kind == "stop":
        if record.get("request") is None:
            if record.get("answer"):
                return f"stop {record.get('device')}: {record['answer']}; last seen in state {record.get('state')}"
            return f"stop {record.get('device')}: reports state {record.get('state')}, which takes no stop request"
        return (f"stop {record.get('device')}: {record.get('request')} {record.get('answer')}; "
                f"now in state {record.get('state')}")
    return f"end: {record.get('outcome')}" + (f" ({record.get('reason')})" if record.get("reason") else "")


def _resumed(record: dict[str, Any]) -> str:
    """The line of a ``stopped``, ``replan`` or ``continue`` record."""
    kind = record["kind"]
    if kind == "stopped":
        at = f" at step {record['step']}" if record.get("step") is not None else ""
        return f"resumes run {record.get('run')}, which {record.get('outcome')}{at}: {record.get('reason')}"
    if kind == "replan":
        states = ", ".join(f"{d} {s}" for d, s in sorted((record.get("states") or {}).items()))
        return f"re-planned {record.get('plan')} from the devices' states ({states}): {record.get('steps')} step(s)"
    return f"continues, confirmed by {record.get('confirmed_by')}"
