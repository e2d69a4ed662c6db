"""Numbers as a safety controller reads them: finite, in ASCII digits, and reported as written."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.reasoning.asp.facts import milli
from tests.reasoning.conftest import BIN_PICKING, write


def _pick(tmp_path: Path, grip_force: str) -> Path:
    return write(tmp_path, "task.yaml", f"task: t\nsteps:\n  - command: pick\n    params: {{grip_force: {grip_force}}}\n")


@pytest.mark.parametrize("command", ["check", "repair", "generate"])
@pytest.mark.parametrize("value, says", [
    ("1e308 kN", ", which in N is beyond any number a device can be given; expected a finite quantity"),
    ("-1e308 kN", ", which in N is beyond any number a device can be given; expected a finite quantity"),
    ("nan N", "; expected a finite number"),
    ("-inf N", "; expected a finite number"),
    ("1e400", "; expected a finite number"),
])
def test_issue_24_a_quantity_that_is_no_finite_number_is_one_line_at_its_line(
        tmp_path: Path, command: str, value: str, says: str) -> None:
    # 1e308 kN became 1e311 N, an infinity: OverflowError traceback in reasoning/asp/facts.py milli
    task = _pick(tmp_path, f"'{value}'")
    extra = ["-o", str(tmp_path / "out")] if command == "generate" else []
    result = CliRunner().invoke(app, [command, str(task), "--cell", str(BIN_PICKING), *extra])
    assert result.exit_code == 2, result.output
    assert result.stderr.splitlines() == [f"{task}:4: step 1 (pick): parameter grip_force is '{value}'{says}"]
    assert result.exception is None or isinstance(result.exception, SystemExit)


@pytest.mark.parametrize("value, shown", [
    ("1.7e305 kN", "1.7e+308 N"),  # was "2e+06 N": ASP's clamped thousandths
    ("150.123456789", "150.123456789 N"),  # was "150.123 N"
    ("'2e9 N'", "2000000000 N"),
])
def test_issue_24_a_value_above_the_maximum_is_reported_with_its_exact_figure(
        tmp_path: Path, value: str, shown: str) -> None:
    (problem,) = service.check(_pick(tmp_path, value), BIN_PICKING).problems
    assert problem.kind == "too_high"
    assert problem.text == f"step 1 (pick): parameter grip_force = {shown} is above its maximum 140 N"


@pytest.mark.parametrize("value", ["'١٢٠ N'", "'𝟒𝟓 N'", "'𝟒𝟓'", "'٤٥'"])
def test_issue_24_only_ascii_digits_make_a_number(tmp_path: Path, value: str) -> None:
    # float() reads Arabic-Indic and mathematical digits: '١٢٠ N' was taken as 120 N
    problems = service.check(_pick(tmp_path, value), BIN_PICKING).problems
    assert [(p.kind, p.parameter) for p in problems] == [("bad_type", "grip_force")]


@pytest.mark.parametrize("value, expected", [
    (float("inf"), None), (float("nan"), None), ("١٢٠", None), ("1e308", 2_000_000_000), (-1e308, -2_000_000_000),
    (0.0015, 2), ("45", 45_000),
])
def test_milli_takes_only_finite_ascii_numbers_and_clamps_without_building_huge_integers(
        value: object, expected: int | None) -> None:
    assert milli(value) == expected


def test_validate_tells_of_a_quantity_beyond_any_number_as_no_number(tmp_path: Path) -> None:
    # it said "is Infinity N; expected a value from 10 to 140 N"
    task = _pick(tmp_path, "'1e308 kN'")
    result = CliRunner().invoke(app, ["validate", str(task)])
    assert result.exit_code == 1
    assert result.stdout.splitlines() == [f"{task}:4: step 1: parameter 'grip_force' takes a number; found 1e308 kN"]
