"""Validation against the vendored W3C schema, with the line of each problem."""

from __future__ import annotations

from pathlib import Path

from plugnproduce.resources import package_file
from plugnproduce.statechart import schema_problems

DATA = Path(__file__).parent / "data"
HEAD = b'<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="a">\n'


def test_the_schema_and_its_licence_ship_in_the_package() -> None:
    folder = package_file("statechart", "io", "w3c")
    assert (folder / "scxml.xsd").is_file() and (folder / "xml.xsd").is_file()
    assert "Copyright" in (folder / "scxml-copyright.xsd").read_text()


def test_a_valid_chart_has_no_problems() -> None:
    assert schema_problems((DATA / "annotated.scxml").read_bytes(), "annotated.scxml") == []


def test_a_dangling_target_is_reported_on_the_transition() -> None:
    data = HEAD + b'<state id="a">\n<transition event="e" target="nowhere"/>\n</state>\n</scxml>'
    (problem,) = schema_problems(data, "dangling.scxml")
    assert problem.line == 3 and "nowhere" in problem.message


def test_an_unexpected_element_is_reported_on_its_line() -> None:
    data = HEAD + b'<state id="a">\n<onentry>\n<goto/>\n</onentry>\n</state>\n</scxml>'
    problems = schema_problems(data, "goto.scxml")
    assert problems and problems[0].line == 4 and problems[0].file == "goto.scxml"


def test_duplicate_ids_are_reported() -> None:
    data = HEAD + b'<state id="a"/>\n<state id="a"/>\n</scxml>'
    assert any("duplicated" in p.message for p in schema_problems(data, "dup.scxml"))
