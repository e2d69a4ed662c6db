"""Help text, ``--version``, ``pnp runs`` and ``pnp report`` without a run id, as a user meets them."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import click
import pytest
import typer.main
from typer.testing import CliRunner

from plugnproduce import __version__
from plugnproduce.cli import app
from plugnproduce.cli.console.helptext import argument_name
from plugnproduce.executor.journal import Journal

runner = CliRunner()


def commands(group: click.Group, path: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], click.Command]]:
    """Every command under ``group`` (sub-groups included), with its name path."""
    for name, command in getattr(group, "commands", {}).items():  # typer's groups are not click.Group
        yield (*path, name), command
        yield from commands(command, (*path, name))


ALL = list(commands(typer.main.get_command(app)))  # type: ignore[arg-type]


def test_version() -> None:
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0 and result.stdout.strip() == f"pnp (plugnproduce) {__version__}"


@pytest.mark.parametrize("path", [p for p, _ in ALL], ids=" ".join)
def test_help_shows_no_type_after_flags(path: tuple[str, ...]) -> None:
    result = runner.invoke(app, [*path, "--help"])
    assert result.exit_code == 0
    assert "<bool>" not in result.stdout


@pytest.mark.parametrize(("path", "command"), ALL, ids=[" ".join(p) for p, _ in ALL])
def test_arguments_are_named_in_capitals(path: tuple[str, ...], command: click.Command) -> None:
    for param in command.params:
        if param.param_type_name == "argument":  # typer's parameters are not click.Argument
            assert argument_name(param).split(".")[0].isupper(), f"{' '.join(path)}: {param.name}"


def journal(folder: Path, name: str, start: float, outcome: str | None, **simulated: float) -> None:
    """A run's journal started at ``start`` (epoch seconds), finished with ``outcome`` 2.5 s later (None: crashed);
    ``speed=F``: on simulated devices working at speed F."""
    times = iter([start, start + 1, start + 2.5])
    with Journal(folder / f"{name}.jsonl", clock=lambda: next(times)) as j:
        j.write("start", task=f"task-{name}", cell="bin-picking", **simulated)
        j.write("step", step=1, command="bin-pick")
        if outcome is not None:
            j.write("end", outcome=outcome)


@pytest.fixture()
def past_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("PNP_RUNS", str(tmp_path))
    journal(tmp_path, "b-second", 2_000_000_000.0, "failed", speed=0.25)
    journal(tmp_path, "a-third", 2_000_000_100.0, None)
    journal(tmp_path, "c-first", 1_900_000_000.0, "succeeded")
    return tmp_path


def test_runs_lists_newest_first(past_runs: Path) -> None:
    result = runner.invoke(app, ["runs"])
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].split() == ["ID", "TASK", "CELL", "START", "STATUS", "SPEED", "DURATION"]
    assert [line.split()[0] for line in lines[1:]] == ["a-third", "b-second", "c-first"]
    assert lines[1].split()[5:] == ["crashed", "-", "1.0", "s"]  # real devices: no speed factor
    assert lines[2].split()[1:3] == ["task-b-second", "bin-picking"]
    assert lines[2].split()[5:] == ["failed", "0.25", "2.5", "s"]  # simulated four times slower


def test_runs_as_json(past_runs: Path) -> None:
    result = runner.invoke(app, ["runs", "--json"])
    runs = json.loads(result.stdout)
    assert [r["id"] for r in runs] == ["a-third", "b-second", "c-first"]
    assert runs[2] == {"id": "c-first", "task": "task-c-first", "cell": "bin-picking",
                       "start": "2030-03-17T17:46:40+00:00", "status": "succeeded", "duration": 2.5,
                       "speed": None, "journal": str(past_runs / "c-first.jsonl")}
    assert runs[1]["speed"] == 0.25


def test_no_runs_yet(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNP_RUNS", str(tmp_path / "none"))
    result = runner.invoke(app, ["runs", "--json"])
    assert result.exit_code == 0 and json.loads(result.stdout) == []


def test_report_without_a_run_shows_the_latest(past_runs: Path) -> None:
    result = runner.invoke(app, ["report"])
    assert result.exit_code == 0
    assert result.stdout.splitlines()[0] == "start task task-a-third on cell bin-picking"
    assert result.stdout.rstrip().endswith("status: crashed; no end record: no safe stop is known to have been sent")


def test_report_without_any_run_is_bad_input(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNP_RUNS", str(tmp_path))
    result = runner.invoke(app, ["report"])
    assert result.exit_code == 2 and "no runs yet" in result.stderr
