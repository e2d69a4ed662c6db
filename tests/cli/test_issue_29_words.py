"""Issue 29: the command line's words, as a user meets them: the same state wording in every command,
help that names arguments as they are typed and lists exit codes, explain's hint, sim plug's refusals."""

from __future__ import annotations

import asyncio
import json
import os
import re
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import click
import pytest
import typer.main
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.errors import ProtocolError
from plugnproduce.sim.cell import SimulatedCell

runner = CliRunner()
CELL = str(service.builtin("cells", "bin-picking.yaml"))
TASK = str(service.builtin("tasks", "bin-picking.yaml"))
GLUE = Path(__file__).parent.parent / "data" / "libraries" / "glue-dispensing"


def every_command(command: click.Command, path: tuple[str, ...] = ()) -> Iterator[tuple[str, ...]]:
    """Every command's name path, the sub-commands of ``pnp sim`` and ``pnp ontology`` too (typer's groups are no
    click.Group), the groups themselves left out."""
    for name, sub in getattr(command, "commands", {}).items():
        if not getattr(sub, "commands", None):
            yield (*path, name)
        yield from every_command(sub, (*path, name))


COMMANDS = list(every_command(typer.main.get_command(app)))


def _help(path: tuple[str, ...]) -> str:
    result = runner.invoke(app, [*path, "--help"], prog_name="pnp")
    assert result.exit_code == 0
    return result.stdout


@pytest.mark.parametrize("path", COMMANDS, ids=" ".join)
def test_help_names_arguments_as_typed_without_python_types(path: tuple[str, ...]) -> None:
    text = _help(path)
    usage = text.splitlines()[0]
    assert "{" not in usage and "}" not in usage, usage
    assert not re.search(r"<[a-z][^>]*>", text), text  # <path>, <str>, <list[Path]>
    assert re.fullmatch(r"Usage: pnp [a-z ]+ \[OPTIONS\]( \[?[A-Z][A-Z.]*(\.ttl)?(\.\.\.)?\]?)*", usage), usage


@pytest.mark.parametrize("path", COMMANDS, ids=" ".join)
def test_every_commands_help_lists_its_exit_codes(path: tuple[str, ...]) -> None:
    text = " ".join(_help(path).split())
    assert "Exit 0 " in text and re.search(r"2 (bad input|unreadable|no such run|an unreadable)", text), text


def test_validate_usage_reads_path_dots() -> None:
    assert _help(("validate",)).splitlines()[0] == "Usage: pnp validate [OPTIONS] PATH..."
    assert _help(("report",)).splitlines()[0] == "Usage: pnp report [OPTIONS] [RUN]"


def test_verify_words_an_implausible_task_as_check_does(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text("task: t\nsteps:\n  - command: close-gripper\n  - command: pick\n", encoding="utf-8")
    checked = runner.invoke(app, ["check", str(task), "--cell", CELL])
    verified = runner.invoke(app, ["verify", str(task), "--cell", CELL])
    assert verified.exit_code == 1
    finding = f"{task}:4: step 2 (pick): device 'gripper' (role 'gripper') is in state 'closed' [closed], "
    assert finding in checked.stdout and finding in verified.stderr
    assert "(pnp:Closed)" not in verified.stderr


def test_explain_of_a_task_without_step_says_how_to_name_the_step() -> None:
    result = runner.invoke(app, ["explain", TASK, "--cell", CELL])
    assert result.exit_code == 2
    assert result.stderr.strip() == (f"{TASK} is a task file: name the step to explain, pnp explain {TASK} --cell "
                                     f"{CELL} --step N (without --step, TARGET is a process command such as pick)")


def _dead_pid() -> int:
    finished = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                              text=True, check=True)
    return int(finished.stdout)


def test_sim_plug_refuses_the_control_address_of_a_stopped_cell(tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HOME", str(tmp_path))
    with socket.create_server(("127.0.0.1", 0)) as listener:  # the port is someone else's now
        listener.settimeout(0.1)
        port = listener.getsockname()[1]
        state = tmp_path / ".cache" / "plugnproduce" / "sim-control.json"
        state.parent.mkdir(parents=True)
        state.write_text(json.dumps({"host": "127.0.0.1", "port": port, "pid": _dead_pid()}))
        result = runner.invoke(app, ["sim", "plug", "gripper"])
        assert result.exit_code == 2
        assert result.stderr.strip() == (f"error: the simulated cell started last (control 127.0.0.1:{port}) has "
                                         "stopped; start one with 'pnp sim up CELL', or name a running one with "
                                         "--control HOST:PORT")
        with pytest.raises(TimeoutError):
            listener.accept()  # nothing was sent to it


def test_sim_plug_says_how_to_go_on_when_the_recorded_cell_does_not_answer(tmp_path: Path,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HOME", str(tmp_path))
    with socket.create_server(("127.0.0.1", 0)) as gone:
        port = gone.getsockname()[1]  # closed when the block ends: nothing listens there
    state = tmp_path / ".cache" / "plugnproduce" / "sim-control.json"
    state.parent.mkdir(parents=True)
    state.write_text(json.dumps({"host": "127.0.0.1", "port": port, "pid": os.getpid()}))
    result = runner.invoke(app, ["sim", "plug", "gripper"])
    assert result.exit_code == 2
    assert result.stderr.strip() == (f"error: simulated cell at 127.0.0.1:{port} does not answer; start a cell with "
                                     "'pnp sim up CELL', or name one with --control HOST:PORT")


def test_plugging_a_library_device_into_a_cell_without_its_library_hints_library() -> None:
    sim = SimulatedCell(service.cell(CELL))
    with pytest.raises(ProtocolError) as refused:
        asyncio.run(sim.plug(str(GLUE / "devices" / "dispenser.ttl")))
    message = str(refused.value)
    assert "dispenser is of unknown class GlueDispenser" in message
    assert message.endswith(f"the cell was started without its library: start it with pnp --library "
                            f"{GLUE.resolve()} sim up CELL")
    with pytest.raises(ProtocolError) as unknown:
        asyncio.run(sim.plug("dispenser"))
    assert str(unknown.value).endswith("a library's device needs the cell started with it: "
                                       "pnp --library LIBRARY sim up CELL")
