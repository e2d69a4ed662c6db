"""Values on the command line are turned into their types as typer turns them, pydantic loaded only when a value
needs it (a number the user typed, a choice): texts, paths, flags and declared defaults need none."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app

runner = CliRunner()
CELL = str(service.builtin("cells", "bin-picking.yaml"))


def test_a_number_out_of_bounds_is_still_refused_with_typers_message() -> None:
    result = runner.invoke(app, ["batch", "--generate", "2", "--top", "0"])
    assert result.exit_code == 2 and "Invalid value for '--top'" in result.output
    assert "greater than or equal to 1" in result.output


def test_a_number_typed_within_bounds_is_taken(tmp_path: Path) -> None:
    out = tmp_path / "out.jsonl"
    result = runner.invoke(app, ["batch", "--generate", "3", "--top", "2", "--seed", "7", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert len(out.read_text(encoding="utf-8").splitlines()) == 3


def test_a_file_name_becomes_a_path_and_a_missing_one_is_one_line() -> None:
    result = runner.invoke(app, ["capabilities", "--cell", CELL])
    assert result.exit_code == 0 and "9 of 12 process commands offered" in result.output
    result = runner.invoke(app, ["capabilities", "--cell", "no-such-cell.yaml"])
    assert result.exit_code == 2 and "no-such-cell.yaml" in result.output


def test_a_repeated_library_option_is_a_list_of_folders(tmp_path: Path) -> None:
    result = runner.invoke(app, ["--library", str(tmp_path / "nowhere"), "capabilities", "--cell", CELL])
    assert result.exit_code == 2 and "nowhere: library folder not found" in result.output
