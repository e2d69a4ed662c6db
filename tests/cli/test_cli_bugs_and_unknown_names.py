"""A bug shows as a bug (exit 4, one line saying so, the traceback in a log file), and a name the user got
wrong as bad input (exit 2, with the nearest known names): a ``KeyError`` no longer passes for either."""

from __future__ import annotations

from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.cli.application import BUG, bug_log

runner = CliRunner()
CELL = str(service.builtin("cells", "bin-picking.yaml"))


@pytest.fixture()
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("PNP_RUNS", str(tmp_path / "runs"))
    return tmp_path


def _raise_key_error() -> list[object]:
    return {}["wrong-key"]  # type: ignore[no-any-return]


def test_a_key_error_raised_by_a_bug_is_exit_4_with_the_traceback_logged(
        home: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(service, "runs", _raise_key_error)
    result = runner.invoke(app, ["runs"])
    log = bug_log()
    assert result.exit_code == BUG == 4  # 3 is an inconclusive verification
    assert result.stderr.strip() == (
        f"error: a bug in plugnproduce, not a mistake in the input (KeyError: 'wrong-key'); the traceback is in "
        f"{log}: please report it with that traceback")
    assert "Traceback" not in result.output
    assert log.is_relative_to(home)
    logged = log.read_text(encoding="utf-8")
    assert "bug in the command runs" in logged and "Traceback (most recent call last)" in logged
    assert "in _raise_key_error" in logged and "KeyError: 'wrong-key'" in logged


def test_any_other_exception_of_a_bug_is_exit_4_too(home: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken() -> list[object]:
        raise AttributeError("'NoneType' object has no attribute 'id'")

    monkeypatch.setattr(service, "runs", broken)
    result = runner.invoke(app, ["runs"])
    assert result.exit_code == 4 and "a bug in plugnproduce" in result.stderr and "AttributeError" in result.stderr


def test_an_unknown_process_command_is_bad_input_with_did_you_mean(home: Path) -> None:
    result = runner.invoke(app, ["explain", "plase", "--cell", CELL])
    assert result.exit_code == 2
    assert result.stderr.strip() == "error: unknown process command 'plase'; did you mean place?"
    assert not bug_log().exists()


def test_an_unknown_run_is_bad_input_with_the_nearest_run_ids(home: Path) -> None:
    (home / "runs").mkdir()
    for run_id in ("bin-picking-20261127-101500", "bin-picking-20261127-111500"):
        (home / "runs" / f"{run_id}.jsonl").write_text("", encoding="utf-8")
    result = runner.invoke(app, ["report", "bin-picking-20261127-10150"])
    assert result.exit_code == 2
    assert result.stderr.strip().startswith("error: unknown run 'bin-picking-20261127-10150'; did you mean "
                                            "bin-picking-20261127-101500")


def test_every_command_answers_through_the_boundary() -> None:
    """A command without it would show a user's typo as a traceback, and a bug as exit 1."""
    def commands(group: object, path: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
        found = []
        for name, command in getattr(group, "commands", {}).items():
            if command.callback is not None and not getattr(command.callback, "under_boundary", False):
                found.append((*path, name))
            found += commands(command, (*path, name))
        return found

    assert commands(typer.main.get_command(app)) == []  # type: ignore[arg-type]
