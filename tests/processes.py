"""Child processes a test starts: stopped in every case, and none left running when the suite ends."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from tests.lines import WAIT


def stop(proc: subprocess.Popen[Any], sig: signal.Signals = signal.SIGTERM) -> int:
    """Ask a process to stop (``sig``), wait for it under the suite's limit, kill it if it does not; its exit code."""
    if proc.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            proc.send_signal(sig)
        try:
            return proc.wait(timeout=WAIT)
        except subprocess.TimeoutExpired:
            proc.kill()
    return proc.wait()


@contextlib.contextmanager
def started(args: list[str], **popen: Any) -> Iterator[subprocess.Popen[Any]]:
    """A child process, stopped (SIGTERM, then killed) however the block ends, unless it was stopped already."""
    proc = subprocess.Popen(args, **popen)
    try:
        yield proc
    finally:
        stop(proc)


def _processes() -> dict[int, tuple[int, str, str]]:
    """Every process: pid → (parent pid, state, command line), from /proc."""
    out = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            cmdline = (stat.parent / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except (OSError, IndexError):
            continue  # ended meanwhile
        out[int(stat.parent.name)] = (int(fields[1]), fields[0], cmdline.strip())
    return out


def running_descendants(pid: int | None = None) -> list[tuple[int, str]]:
    """(pid, command line) of every process below ``pid`` (this one) that is still running (not a zombie)."""
    table = _processes()
    below, todo = [], [os.getpid() if pid is None else pid]
    while todo:
        parent = todo.pop()
        children = [p for p, (ppid, _, _) in table.items() if ppid == parent]
        below += children
        todo += children
    return [(p, table[p][2]) for p in sorted(below) if table[p][1] != "Z"]


def ours(cmdline: str) -> bool:
    """Whether a command line is one the tests start: the controller (``python -m plugnproduce``) or ``pnp``."""
    words = cmdline.split()
    return "plugnproduce" in words or any(Path(w).name == "pnp" for w in words[:2])
