"""Output piped into a reader that stops early (``pnp report RUN | head``): no error, the command's own exit code."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.cli.console.pipes import QuietPipe
from tests.lines import WAIT
from tests.processes import stop

TASKS = service.builtin("tasks")
CELL = str(service.builtin("cells", "bin-picking.yaml"))


def closed_early(*args: str) -> tuple[int, str]:
    """Run ``pnp ARGS`` with stdout a pipe whose reader reads one line and leaves; exit code and stderr."""
    proc = subprocess.Popen([sys.executable, "-m", "plugnproduce", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stderr is not None
    try:
        proc.stdout.readline()
        proc.stdout.close()
        err = proc.stderr.read()
        proc.stderr.close()
        return proc.wait(timeout=WAIT), err
    finally:
        stop(proc)  # no effect once it has exited


def long_journal(path: Path, events: int = 5000) -> Path:
    """A finished run's journal far longer than a pipe's buffer."""
    records = [{"seq": 1, "t": 1.0, "kind": "start", "task": "t", "cell": "c"}]
    records += [{"seq": i + 2, "t": 1.0 + i / 1000, "kind": "event", "device": "robot", "event": f"e{i}"}
                for i in range(events)]
    records.append({"seq": events + 2, "t": 9.0, "kind": "end", "outcome": "succeeded"})
    path.write_text("".join(json.dumps(r) + "\n" for r in records), encoding="utf-8")
    return path


def test_report_piped_to_head_ends_quietly(tmp_path: Path) -> None:
    code, err = closed_early("report", str(long_journal(tmp_path / "run.jsonl")))
    assert (code, err) == (0, "")


def test_an_implausible_check_piped_to_head_still_exits_1() -> None:
    code, err = closed_early("check", str(TASKS / "bin-picking-invalid.yaml"), "--cell", CELL)
    assert (code, err) == (1, "")


def test_capabilities_piped_to_head_ends_quietly() -> None:
    code, err = closed_early("capabilities", "--cell", CELL)
    assert (code, err) == (0, "")


class Gone(io.StringIO):
    """A stream whose reader has gone."""

    def write(self, text: str) -> int:
        raise BrokenPipeError(32, "Broken pipe")

    def flush(self) -> None:
        raise BrokenPipeError(32, "Broken pipe")


@pytest.mark.parametrize("first", ["write", "flush"])
def test_after_a_broken_pipe_output_is_dropped(first: str) -> None:
    pipe = QuietPipe(Gone())
    if first == "write":
        assert pipe.write("lost\n") == 5
    else:
        pipe.flush()
    assert pipe.closed_by_reader and pipe.write("also lost\n") == 10
