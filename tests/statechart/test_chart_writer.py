"""Writing the model back: deterministic bytes, round trips, annotations and prefixes kept."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart, read_chart, schema_problems, write_chart
from plugnproduce.statechart.model import PNP_NS, Chart, Final, Send, State, Transition

DATA = Path(__file__).parent / "data"
CHARTS = sorted(descriptions_path().glob("*/*.scxml")) + [DATA / "annotated.scxml"]


@pytest.mark.parametrize("path", CHARTS, ids=lambda p: p.name)
def test_write_read_write_is_byte_identical(path: Path) -> None:
    once = write_chart(read_chart(path))
    assert write_chart(parse_chart(once, path)) == once


@pytest.mark.parametrize("path", CHARTS, ids=lambda p: p.name)
def test_read_of_write_gives_the_same_model(path: Path) -> None:
    chart = read_chart(path)
    assert parse_chart(write_chart(chart), path) == chart


@pytest.mark.parametrize("path", CHARTS, ids=lambda p: p.name)
def test_written_charts_stay_schema_valid(path: Path) -> None:
    assert schema_problems(write_chart(read_chart(path)), path) == []


def test_pretty_printed_with_declaration() -> None:
    text = write_chart(read_chart(DATA / "annotated.scxml")).decode()
    lines = text.splitlines()
    assert lines[0] == '<?xml version="1.0" encoding="UTF-8"?>'
    assert lines[1].startswith('<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:my="http://example.org/mine#"')
    assert lines[2] == "  <datamodel>"
    assert '    <data id="count" expr="0"/>' in lines
    assert text.endswith("</scxml>\n")


def test_the_ontology_prefix_is_always_pnp() -> None:
    source = (b'<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:onto="http://plugnproduce.org/ontology#" '
              b'version="1.0"><state id="a" onto:concept="Open"/></scxml>')
    text = write_chart(parse_chart(source, "onto.scxml")).decode()
    assert 'xmlns:pnp="http://plugnproduce.org/ontology#"' in text
    assert '<state id="a" pnp:concept="Open"/>' in text
    assert "onto:" not in text


def test_unknown_namespaces_keep_their_prefix_or_get_a_stable_one() -> None:
    kept = (b'<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:x="urn:x" version="1.0">'
            b'<state id="a" x:k="1"/></scxml>')
    assert b'x:k="1"' in write_chart(parse_chart(kept, "kept.scxml"))
    built = Chart(children=[State(id="a", extra_attrs={"{urn:b}k": "1", "{urn:a}k": "2"})])
    text = write_chart(built).decode()
    assert 'xmlns:ns0="urn:a" xmlns:ns1="urn:b"' in text
    assert '<state id="a" ns0:k="2" ns1:k="1"/>' in text


def test_a_chart_built_in_code_round_trips() -> None:
    send = Send(event="xirp.request.Open", type="xirp", target="gripper")
    chart = Chart(name="built", initial=["a"], datamodel="python", children=[
        State(id="a", extra_attrs={"{" + PNP_NS + "}concept": "Open"},
              transitions=[Transition(event="go", targets=["done"], actions=[send])]),
        Final(id="done"),
    ])
    data = write_chart(chart)
    assert parse_chart(data, "built.scxml") == chart
    assert schema_problems(data, "built.scxml") == []


def test_inline_markup_is_written_as_read() -> None:
    chart = read_chart(DATA / "annotated.scxml")
    text = write_chart(chart).decode()
    assert '<data id="doc"><part xmlns="" id="a"><sub></sub></part></data>' in text
    assert parse_chart(text.encode(), "again.scxml").data[2].markup == chart.data[2].markup


def test_text_with_special_characters_survives() -> None:
    chart = Chart(children=[State(id="a", transitions=[Transition(cond="x < 3 and y == '&'", targets=["a"])])])
    assert parse_chart(write_chart(chart), "c.scxml") == chart
