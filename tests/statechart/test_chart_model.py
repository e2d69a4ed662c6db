"""The neutral model: document order, look-ups, the pnp:concept convenience."""

from __future__ import annotations

from pathlib import Path

from plugnproduce.statechart import Chart, Final, State, concept, parse_chart, read_chart, write_chart
from plugnproduce.statechart.model import CONCEPT, Send, Transition, walk

DATA = Path(__file__).parent / "data"


def test_states_come_in_document_order() -> None:
    chart = read_chart(DATA / "annotated.scxml")
    ids = [s.id for s in chart.states()]
    assert ids == ["cell", "robot", "robot_hist", "robot_idle", "robot_moving", "helper", "helper_a",
                   "helper_done"]


def test_states_can_leave_out_history() -> None:
    chart = read_chart(DATA / "annotated.scxml")
    assert "robot_hist" not in [s.id for s in chart.states(include_history=False)]


def test_find_and_parent_of() -> None:
    chart = read_chart(DATA / "annotated.scxml")
    idle = chart.find("robot_idle")
    assert isinstance(idle, State)
    parent = chart.parent_of(idle)
    assert isinstance(parent, State) and parent.id == "robot"
    assert chart.parent_of(chart.children[0]) is chart
    assert chart.find("no_such_state") is None


def test_concept_of_annotated_and_plain_states() -> None:
    chart = read_chart(DATA / "annotated.scxml")
    assert concept(chart.find("robot_moving")) == "Moving"
    assert concept(chart.find("helper_a")) is None


def test_equality_ignores_source_lines() -> None:
    a = State(id="s", line=3, extra_attrs={CONCEPT: "Open"})
    b = State(id="s", line=40, extra_attrs={CONCEPT: "Open"})
    assert a == b
    assert a != State(id="s", extra_attrs={CONCEPT: "Closed"})


def test_walk_reaches_executable_content_and_inline_charts() -> None:
    chart = read_chart(DATA / "annotated.scxml")
    sends = [n for n in walk(chart) if isinstance(n, Send)]
    assert [s.event for s in sends] == ["xirp.request.Move", "motion.done"]
    finals = [n for n in walk(chart) if isinstance(n, Final)]
    assert [f.id for f in finals] == ["c0", "helper_done"]
    assert not any(isinstance(n, Final) and n.id == "c0" for n in walk(chart, into_charts=False))


def test_transition_splits_event_descriptors() -> None:
    assert Transition(event="a.b  c.*", targets=["x"]).events == ["a.b", "c.*"]
    assert Transition(targets=["x"]).events == []


def test_a_chart_built_in_code_has_no_lines_and_its_written_text_read_back_has_each_states_line() -> None:
    """Findings on a chart name a line only where one exists: none in code, the written text's once read."""
    chart = Chart(name="built", initial=["a"], children=[State(id="a"), Final(id="done")])
    assert [s.line for s in chart.states()] == [None, None]
    text = write_chart(chart)
    again = parse_chart(text, "built.scxml")
    lines = text.decode().splitlines()
    where = {s.id: next(n for n, line in enumerate(lines, start=1) if f'id="{s.id}"' in line) for s in chart.states()}
    assert [(s.id, s.line) for s in again.states()] == [("a", where["a"]), ("done", where["done"])]
    assert where["a"] != where["done"]
    assert again == chart  # lines do not take part in comparing nodes
