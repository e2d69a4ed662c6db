"""Reading SCXML into the model: every element, annotations kept, errors that say where."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.errors import DescriptionError, HostileInputError, UnreadableError
from plugnproduce.statechart import parse_chart, read_chart
from plugnproduce.statechart.model import (
    PNP_NS,
    Cancel,
    Chart,
    Data,
    Foreach,
    History,
    If,
    Invoke,
    Log,
    Parallel,
    Raise,
    Send,
    State,
)

DATA = Path(__file__).parent / "data"
PNP = "{" + PNP_NS + "}"
SCXML_OPEN = '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0">'


@pytest.fixture(scope="module")
def chart() -> Chart:
    return read_chart(DATA / "annotated.scxml")


def test_document_attributes(chart: Chart) -> None:
    assert (chart.name, chart.initial, chart.datamodel, chart.binding) == ("annotated", ["cell"], "python", "early")
    assert chart.extra_attrs == {PNP + "role": "demo"}


def test_annotations_in_clark_notation(chart: Chart) -> None:
    idle = chart.find("robot_idle")
    assert idle.extra_attrs == {PNP + "concept": "Idle", "{http://example.org/mine#}note": "kept"}
    transition = idle.transitions[0]
    assert transition.extra_attrs == {PNP + "params": "pose speed"}
    send = transition.actions[0]
    assert isinstance(send, Send) and send.params[0].extra_attrs == {PNP + "unit": "m/s"}


def test_source_lines(chart: Chart) -> None:
    assert chart.find("robot_idle").line == 15
    assert chart.find("robot_idle").transitions[0].line == 20


def test_data_values(chart: Chart) -> None:
    count, items, doc = chart.data
    assert count == Data(id="count", expr="0")
    assert items.text == "[1, 2, 3]"
    assert doc.markup == '<part id="a"><sub></sub></part>'


def test_send_attributes(chart: Chart) -> None:
    send = chart.find("robot_idle").transitions[0].actions[0]
    assert (send.event, send.type, send.target, send.namelist) == ("xirp.request.Move", "xirp", "robot", ["count"])
    assert (send.params[0].name, send.params[0].expr) == ("Speed", "0.5")
    delayed = chart.find("robot_moving").onentry[0].actions[0]
    assert (delayed.id, delayed.delay) == ("t1", "300ms")


def test_if_elseif_else(chart: Chart) -> None:
    node = chart.find("robot_moving").onentry[0].actions[1]
    assert isinstance(node, If)
    assert node.cond == "count == 1" and node.actions == [Raise(event="first")]
    assert [b.cond for b in node.elseifs] == ["count == 2"]
    assert node.elseifs[0].actions == [Raise(event="second")]
    loop = node.orelse.actions[0]
    assert isinstance(loop, Foreach) and (loop.array, loop.item, loop.index) == ("items", "x", "i")
    assert loop.actions == [Log(expr="x")]


def test_history_transition_type_and_cancel(chart: Chart) -> None:
    history = chart.find("robot_hist")
    assert isinstance(history, History) and history.type == "deep"
    assert history.transition.targets == ["robot_idle"]
    moving = chart.find("robot_moving")
    assert moving.transitions[0].type == "internal"
    assert moving.onexit[0].actions == [Cancel(sendid="t1")]


def test_initial_element_and_attribute(chart: Chart) -> None:
    robot, helper = chart.find("robot"), chart.find("helper")
    assert robot.initial_element.transition.targets == ["robot_idle"] and robot.initial == []
    assert helper.initial == ["helper_a"] and helper.initial_element is None
    assert isinstance(chart.find("cell"), Parallel)


def test_invoke_with_inline_chart(chart: Chart) -> None:
    invoke = chart.find("helper_a").invokes[0]
    assert isinstance(invoke, Invoke)
    assert (invoke.id, invoke.type, invoke.autoforward) == ("child", "scxml", True)
    child = invoke.content.chart
    assert child is not None and child.initial == ["c0"]
    assert child.find("c0").donedata.params[0].name == "result"
    assert invoke.finalize.actions == [Log(expr="_event.name")]


def test_donedata_content(chart: Chart) -> None:
    assert chart.find("helper_done").donedata.content.expr == "count"


@pytest.mark.parametrize(
    ("name", "line", "found", "expected"),
    [
        ("missing_target.scxml", 3, "'nowhere' does not exist", "expected the id of a state"),
        ("missing_initial.scxml", 1, "'start', which does not exist", "expected the id of a state"),
        ("unknown_element.scxml", 4, "found <goto> in <onentry>", "expected executable content"),
        ("unknown_attribute.scxml", 2, "unknown attribute 'intial' on <state>", "expected one of id, initial"),
    ],
)
def test_structural_errors_say_what_and_where(name: str, line: int, found: str, expected: str) -> None:
    with pytest.raises(DescriptionError) as info:
        read_chart(DATA / name)
    error = info.value
    assert (Path(error.file).name, error.line) == (name, line)
    assert found in error.message and expected in error.message


@pytest.mark.parametrize(
    ("body", "found"),
    [
        ('<state id="a"/><state id="a"/>', "'a' is used twice"),
        ('<state id="a" initial="b"><state id="c"/></state><state id="b"/>', "not inside state 'a'"),
        ('<state id="a"><raise event="x"/></state>', "found <raise> in <state>"),
        ('<state id="a" xmlns:s="http://www.w3.org/2005/07/scxml" s:id="b"/>', "in the SCXML namespace"),
        ('<state id="a"><my:thing xmlns:my="urn:x"/></state>', "foreign element"),
        ('<state id="a"><onentry><send event="a" eventexpr="b"/></onentry></state>', "both 'event' and 'eventexpr'"),
        ('<state id="a"><onentry><raise/></onentry></state>', "lacks the required attribute 'event'"),
        ('<state id="a"><transition type="sideways"/></state>', "expected 'external' or 'internal'"),
        ("", "the chart has no state"),
    ],
)
def test_invalid_documents(body: str, found: str) -> None:
    with pytest.raises(DescriptionError, match=found):
        parse_chart(f"{SCXML_OPEN}{body}</scxml>".encode(), "inline.scxml")


def test_root_must_be_scxml_in_its_namespace() -> None:
    with pytest.raises(DescriptionError, match=r"found <scxml> at the top; expected <scxml> in the namespace"):
        parse_chart(b'<scxml version="1.0"><state id="a"/></scxml>', "plain.scxml")


def test_hostile_and_malformed_input_is_refused() -> None:
    bomb = b'<?xml version="1.0"?><!DOCTYPE x [<!ENTITY a "aaaa">]><scxml/>'
    with pytest.raises(HostileInputError):
        parse_chart(bomb, "bomb.scxml")
    with pytest.raises(UnreadableError, match="malformed XML"):
        parse_chart(b"<scxml", "broken.scxml")


def test_top_level_executable_content_is_kept() -> None:
    chart = parse_chart(f'{SCXML_OPEN}<script>x = 1</script><state id="a"/></scxml>'.encode(), "s.scxml")
    assert chart.scripts[0].text == "x = 1"
    assert isinstance(chart.children[0], State)
