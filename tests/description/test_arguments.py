"""A device's argument contracts as read from its description, and the units they are written in."""

from __future__ import annotations

import math

import pytest
from typer.testing import CliRunner

from plugnproduce.cli import app
from plugnproduce.description.quantities.units import Amount, UnitError, convert, read_amount, unit_known
from tests.conftest import edit


def test_the_grippers_force_contract_is_read(device_copy, taxonomy) -> None:
    from plugnproduce.description.loader import load_device

    ttl, _ = device_copy("gripper")
    close = load_device(ttl, taxonomy).argument("Close", "http://plugnproduce.org/ontology#GripForce")
    assert (close.required, close.unit, close.minimum, close.maximum, close.default) == (True, "N", 20, 100, None)
    assert close.where is not None and close.where.line == 20


def test_an_undeclared_accepted_quantity_stays_required_without_limits(device_copy, taxonomy) -> None:
    from plugnproduce.description.loader import load_device

    ttl, _ = device_copy("magnetic-gripper")
    device = load_device(ttl, taxonomy)
    contract = device.argument("Anything", "http://plugnproduce.org/ontology#GripForce")
    assert contract.needed and contract.minimum is None and contract.unit == ""


@pytest.mark.parametrize("old, new, code, needle", [
    ('pnp:request "Close"', 'pnp:request "Squeeze"', 1, "no transition of the chart waits for request Squeeze"),
    ('pnp:unit "N"', 'pnp:unit "newtonish"', 1, "unknown unit 'newtonish'"),
    ("pnp:maxValue 100", 'pnp:maxValue "lots"', 2, "maximum 'lots' is not a finite number"),
])
def test_a_bad_argument_is_one_line_at_its_place(device_copy, old: str, new: str, code: int, needle: str) -> None:
    ttl, _ = device_copy("gripper")
    edit(ttl, old, new)
    result = CliRunner().invoke(app, ["validate", str(ttl)])
    assert result.exit_code == code
    assert result.output.startswith(f"{ttl}:20: ") and needle in result.output, result.output
    assert "Traceback" not in result.output


@pytest.mark.parametrize("text, amount", [
    ("120 N", Amount(120.0, "N")), ("0.12 kN", Amount(0.12, "kN")), ("-60 kPa", Amount(-60.0, "kPa")),
    ("45", Amount(45.0, "")), ("2.5e1 mm/s", Amount(25.0, "mm/s")),
])
def test_a_quantity_is_a_number_and_a_unit(text: str, amount: Amount | None) -> None:
    assert read_amount(text) == amount


def test_a_number_that_is_not_finite_is_read_so_that_the_check_can_refuse_it() -> None:
    amount = read_amount("nan N")
    assert amount is not None and math.isnan(amount.number) and amount.unit == "N"


@pytest.mark.parametrize("value", ["firm", "0.4 0.1 0.2 0 180 0", True, [1, 2], "9" * 70])
def test_other_values_are_no_quantity(value: object) -> None:
    assert read_amount(value) is None


def test_units_convert_within_a_dimension_only() -> None:
    assert convert(0.12, "kN", "N") == pytest.approx(120)
    assert convert(250, "mm", "m") == pytest.approx(0.25)
    assert convert(50, "%", "") == 50  # no unit on one side: the number as it is
    with pytest.raises(UnitError, match="kg cannot be converted to N"):
        convert(12, "kg", "N")
    assert unit_known("N m") and unit_known("%") and not unit_known("__import__('os')")


@pytest.mark.parametrize("unit", ["N**9**9**9", "kg/0", "degC*m", "__import__('os')", "N" * 70])
def test_a_hostile_or_meaningless_unit_is_refused_quickly(unit: str) -> None:
    with pytest.raises(UnitError):
        convert(5, unit, "N")


@pytest.mark.parametrize("value, code, needle", [
    ("0.12 kN", 0, "1 files valid"),
    ("1.2 kN", 1, "parameter 'grip_force' is 1200.0 N; expected a value from 10 to 140 N"),
    ("12 kg", 1, "parameter 'grip_force' takes a number; found 12 kg"),
])
def test_validate_reads_a_quantity_in_its_parameters_unit(tmp_path, value: str, code: int, needle: str) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(f"task: t\nsteps:\n  - command: pick\n    params: {{grip_force: {value}}}\n")
    result = CliRunner().invoke(app, ["validate", str(task)])
    assert result.exit_code == code and needle in result.output
