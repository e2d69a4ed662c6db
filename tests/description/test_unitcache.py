"""Units answered from the table cached in the user's folder: pint's answers, pint loaded only for what is new."""

from __future__ import annotations

import json
import random
from pathlib import Path

import pint
import pytest

from plugnproduce.description.quantities.unitcache import UnitTable, table_file

PAIRS = [("kN", "N"), ("N", "kN"), ("mm/s", "m/s"), ("km/h", "m/s"), ("deg", "rad"), ("percent", "dimensionless"),
         ("N m", "N mm"), ("kPa", "bar"), ("ms", "s"), ("m deg", "mm rad"), ("lbf", "N"), ("inch", "mm")]
UREG = pint.UnitRegistry()


def test_the_table_gives_pints_own_numbers_and_the_next_process_reads_them_without_pint(tmp_path: Path) -> None:
    rng = random.Random(28)
    values = [rng.uniform(-1e6, 1e6) for _ in range(50)] + [0.14, 0.1 + 0.2, 1e-300, 5e307]
    path = tmp_path / "units.json"
    first = UnitTable(path)
    expected = {(a, b): [float(UREG.Quantity(v, a).to(b).magnitude) for v in values] for a, b in PAIRS}
    assert {(a, b): [first.Quantity(v, a).to(b).magnitude for v in values] for a, b in PAIRS} == expected
    again = UnitTable(path)
    assert {(a, b): [again.Quantity(v, a).to(b).magnitude for v in values] for a, b in PAIRS} == expected
    assert again._pint is None  # every answer came from the file


def test_units_of_other_dimensions_are_remembered_as_such(tmp_path: Path) -> None:
    path = tmp_path / "units.json"
    with pytest.raises(pint.DimensionalityError):
        UnitTable(path).Quantity(1.0, "kg").to("N")
    again = UnitTable(path)
    with pytest.raises(ValueError, match="kg cannot be converted to N"):
        again.Quantity(1.0, "kg").to("N")
    assert again._pint is None


def test_an_unknown_unit_is_pints_error_and_is_not_remembered(tmp_path: Path) -> None:
    path = tmp_path / "units.json"
    table = UnitTable(path)
    assert table.Unit("kN") == "kN"
    with pytest.raises(pint.UndefinedUnitError):
        table.Unit("furlongz")
    doc = json.loads(path.read_text())
    assert doc["units"] == ["kN"]


def test_an_offset_unit_is_converted_by_pint_every_time(tmp_path: Path) -> None:
    path = tmp_path / "units.json"
    assert UnitTable(path).Quantity(20.0, "degC").to("K").magnitude == pytest.approx(293.15)
    assert "degC\tK" not in (json.loads(path.read_text())["factors"] if path.exists() else {})
    assert UnitTable(path).Quantity(68.0, "degF").to("degC").magnitude == pytest.approx(20.0)


def test_a_damaged_or_foreign_file_is_ignored_and_rewritten(tmp_path: Path) -> None:
    path = tmp_path / "units.json"
    for text in ("{not json", json.dumps({"format": 99, "units": ["x"], "factors": {}}),
                 json.dumps({"format": 1, "units": "N", "factors": {"kN\tN": "many"}})):
        path.write_text(text)
        assert UnitTable(path).Quantity(2.0, "kN").to("N").magnitude == 2000.0
        assert json.loads(path.read_text())["factors"] == {"kN\tN": 1000.0}


def test_processes_writing_at_once_keep_each_others_answers(tmp_path: Path) -> None:
    path = tmp_path / "units.json"
    a, b = UnitTable(path), UnitTable(path)
    a.Quantity(1.0, "kN").to("N")
    b.Quantity(1.0, "mm").to("m")
    assert json.loads(path.read_text())["factors"] == {"kN\tN": 1000.0, "mm\tm": 0.001}


def test_the_file_is_named_for_the_installed_pint(tmp_path: Path) -> None:
    path = table_file(tmp_path)
    assert path is not None and path.parent == tmp_path and path.name.startswith("units-")
    assert table_file(tmp_path) == path
