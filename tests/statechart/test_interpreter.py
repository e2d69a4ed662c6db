"""The runtime on small charts: the behaviour a user of :class:`Interpreter` relies on."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.errors import ExecutionError
from plugnproduce.statechart import SCXML_NS, parse_chart
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.events import ERROR, LOG, Event, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter


def session(body: str, initial: str | None = None, **options: object) -> Interpreter:
    """An interpreter for a chart with the Python datamodel whose children are ``body``."""
    first = f' initial="{initial}"' if initial else ""
    text = f'<scxml xmlns="{SCXML_NS}" version="1.0" datamodel="python"{first}>{body}</scxml>'
    return Interpreter(parse_chart(text.encode(), "test chart"), **options)  # type: ignore[arg-type]


def started(body: str, initial: str | None = None, **options: object) -> Interpreter:
    interpreter = session(body, initial, **options)
    interpreter.start()
    return interpreter


class Recorder:
    """Meta events of one kind, as an observer."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.seen: list[MetaEvent] = []

    def __call__(self, meta: MetaEvent) -> None:
        if meta.name == self.kind:
            self.seen.append(meta)


# --- parallel regions: document order and conflicts -------------------------------------

TWO_REGIONS = """
<datamodel><data id="order" expr="[]"/></datamodel>
<parallel id="p">
  <state id="r1" initial="a1">
    <state id="a1">
      <onexit><assign location="order" expr="order + ['exit a1']"/></onexit>
      <transition event="go" target="a2"><assign location="order" expr="order + ['take r1']"/></transition>
    </state>
    <state id="a2"><onentry><assign location="order" expr="order + ['enter a2']"/></onentry></state>
  </state>
  <state id="r2" initial="b1">
    <state id="b1">
      <onexit><assign location="order" expr="order + ['exit b1']"/></onexit>
      <transition event="go" target="b2"><assign location="order" expr="order + ['take r2']"/></transition>
    </state>
    <state id="b2"><onentry><assign location="order" expr="order + ['enter b2']"/></onentry></state>
  </state>
</parallel>
"""


def test_parallel_regions_take_their_transitions_in_document_order() -> None:
    interpreter = started(TWO_REGIONS)
    interpreter.queue("go").execute()
    assert interpreter.datamodel["order"] == ["exit b1", "exit a1", "take r1", "take r2", "enter a2", "enter b2"]
    assert interpreter.configuration == ["p", "r1", "a2", "r2", "b2"]


def test_a_transition_leaving_the_parallel_state_preempts_a_later_region() -> None:
    interpreter = started("""
    <parallel id="p">
      <state id="r1"><state id="a1"><transition event="go" target="out"/></state></state>
      <state id="r2" initial="b1">
        <state id="b1"><transition event="go" target="b2"/></state>
        <state id="b2"/>
      </state>
    </parallel>
    <state id="out"/>""")
    step = interpreter.queue("go").execute_once()
    assert step is not None and [(t.source, t.targets) for t in step.transitions] == [("a1", ("out",))]
    assert interpreter.configuration == ["out"]


def test_a_descendant_transition_wins_over_a_conflicting_ancestor_transition() -> None:
    interpreter = started("""
    <state id="top" initial="p">
      <transition event="go" target="out"/>
      <parallel id="p">
        <state id="r1"><state id="a1"/></state>
        <state id="r2" initial="b1">
          <state id="b1"><transition event="go" target="b2"/></state>
          <state id="b2"/>
        </state>
      </parallel>
    </state>
    <state id="out"/>""")
    interpreter.queue("go").execute()
    assert interpreter.configuration == ["top", "p", "r1", "a1", "r2", "b2"]


# --- eventless transitions, In(), done events ---------------------------------------------


def test_eventless_transitions_run_until_the_configuration_is_stable() -> None:
    interpreter = session("""
    <datamodel><data id="n" expr="0"/></datamodel>
    <state id="count">
      <onentry><assign location="n" expr="n + 1"/></onentry>
      <transition cond="n &lt; 3" target="count"/>
      <transition target="done"/>
    </state>
    <final id="done"/>""")
    step = interpreter.start()
    assert (interpreter.running, interpreter.final_state, interpreter.datamodel["n"]) == (False, "done", 3)
    assert [t.targets for t in step.transitions] == [("count",), ("count",), ("done",)]


def test_a_condition_can_ask_whether_another_region_is_in_a_state() -> None:
    interpreter = started("""
    <parallel id="p">
      <state id="r1" initial="a1">
        <state id="a1"><transition event="go" target="a2"/></state>
        <state id="a2"/>
      </state>
      <state id="r2" initial="b1">
        <state id="b1"><transition cond="In('a2') and not In('nowhere')" target="b2"/></state>
        <state id="b2"/>
      </state>
    </parallel>""")
    assert interpreter.is_active("b1")
    interpreter.queue("go").execute()
    assert interpreter.is_active("a2") and interpreter.is_active("b2")


def test_a_parallel_state_is_done_when_every_region_is() -> None:
    interpreter = started("""
    <parallel id="p">
      <state id="r1" initial="a">
        <state id="a"><transition event="a.finish" target="a_end"/></state>
        <final id="a_end"/>
      </state>
      <state id="r2" initial="b">
        <state id="b"><transition event="b.finish" target="b_end"/></state>
        <final id="b_end"/>
      </state>
      <transition event="done.state.p" target="finished"/>
    </parallel>
    <final id="finished"/>""")
    first = interpreter.queue("a.finish").execute_once()
    assert first is not None and [e.name for e in first.consumed] == ["a.finish", "done.state.r1"]
    assert interpreter.running
    second = interpreter.queue("b.finish").execute_once()
    assert second is not None and [e.name for e in second.consumed] == ["b.finish", "done.state.r2", "done.state.p"]
    assert interpreter.final_state == "finished"


# --- time: delayed sends against a manual clock -------------------------------------------

TIMER = """
<state id="waiting">
  <onentry><send id="timer" event="timeout" delay="2s"/></onentry>
  <transition event="stop.timer"><cancel sendid="timer"/></transition>
  <transition event="timeout" target="timed_out"/>
</state>
<state id="timed_out"/>"""


def test_a_delayed_send_arrives_when_the_clock_reaches_it() -> None:
    clock = ManualClock()
    interpreter = started(TIMER, clock=clock)
    assert interpreter.next_due() == 2.0
    clock.advance(1.5)
    assert interpreter.execute() == [] and interpreter.is_active("waiting")
    clock.advance(0.5)
    steps = interpreter.execute()
    assert [s.event.name for s in steps if s.event is not None] == ["timeout"]
    assert interpreter.is_active("timed_out") and interpreter.next_due() is None


def test_a_cancelled_send_never_arrives() -> None:
    clock = ManualClock()
    interpreter = started(TIMER, clock=clock)
    interpreter.queue("stop.timer").execute()
    assert interpreter.next_due() is None
    clock.advance(10)
    interpreter.execute()
    assert interpreter.is_active("waiting")


# --- I/O processors ---------------------------------------------------------------------


class Device:
    """An I/O processor that keeps what it is asked to send."""

    location = "xirp://cell/gripper"

    def __init__(self, fails: bool = False) -> None:
        self.fails = fails
        self.sent: list[tuple[str, str | None, str, object]] = []

    def send(self, event: Event, target: str | None, type: str) -> None:  # noqa: A002 - the SCXML name
        if self.fails:
            raise ConnectionError("the gripper does not answer")
        self.sent.append((event.name, target, type, event.data))


COMMAND = """
<state id="closing">
  <onentry>
    <send type="xirp" target="gripper" event="request.Close"><param name="GripForce" expr="45"/></send>
  </onentry>
  <transition event="error.communication" target="unreachable"/>
  <transition event="error.execution" target="refused"/>
</state>
<state id="unreachable"/>
<state id="refused"/>"""


def test_a_send_of_a_registered_type_goes_to_its_io_processor() -> None:
    device = Device()
    interpreter = started(COMMAND, io_processors={"xirp": device})
    assert device.sent == [("request.Close", "gripper", "xirp", {"GripForce": 45})]
    assert interpreter.is_active("closing")
    assert interpreter.datamodel["_ioprocessors"]["xirp"]["location"] == "xirp://cell/gripper"


def test_an_io_processor_that_fails_gives_the_chart_error_communication() -> None:
    interpreter = started(COMMAND, io_processors={"xirp": Device(fails=True)})
    assert interpreter.is_active("unreachable")


def test_a_send_of_an_unknown_type_gives_the_chart_error_execution() -> None:
    errors = Recorder(ERROR)
    interpreter = session(COMMAND)
    interpreter.attach(errors)
    interpreter.start()
    assert interpreter.is_active("refused")
    assert "send type 'xirp' has no I/O processor" in errors.seen[0].data["event"].data["message"]


# --- the restricted evaluator -------------------------------------------------------------

SCRIPT = """
<datamodel><data id="answer" expr="0"/></datamodel>
<script>answer = 6 * 7</script>
<state id="idle"/>"""


def test_script_is_refused_unless_the_interpreter_is_trusted() -> None:
    with pytest.raises(ExecutionError, match=r"<script> runs arbitrary code and is refused.*trusted=True"):
        session(SCRIPT)


def test_script_runs_in_a_trusted_interpreter() -> None:
    assert started(SCRIPT, trusted=True).datamodel["answer"] == 42


@pytest.mark.parametrize("expression", ["__import__('os')", "().__class__.__bases__", "open('/etc/passwd')"])
def test_expressions_outside_the_allow_list_are_refused(expression: str) -> None:
    errors = Recorder(ERROR)
    interpreter = session(f"""
    <datamodel><data id="x" expr="{expression}"/></datamodel>
    <state id="s"><transition event="error.execution" target="refused"/></state>
    <state id="refused"/>""")
    interpreter.attach(errors)
    interpreter.start()
    assert interpreter.is_active("refused") and interpreter.datamodel["x"] is None
    assert "not allowed by the restricted evaluator" in errors.seen[0].data["event"].data["message"]


def test_an_error_stops_the_rest_of_its_block_and_reaches_the_chart() -> None:
    interpreter = started("""
    <datamodel><data id="seen" expr="[]"/></datamodel>
    <state id="s">
      <onentry>
        <assign location="seen" expr="seen + ['before']"/>
        <assign location="seen" expr="missing + 1"/>
        <assign location="seen" expr="seen + ['after']"/>
      </onentry>
      <transition event="error.execution" target="failed"/>
    </state>
    <state id="failed"/>""")
    assert interpreter.datamodel["seen"] == ["before"]
    assert interpreter.is_active("failed")


# --- the session as a whole ---------------------------------------------------------------


def test_observers_see_logs_and_the_session_starts_only_once() -> None:
    logs = Recorder(LOG)
    interpreter = session('<final id="end"><onentry><log label="outcome" expr="1 + 1"/></onentry></final>')
    interpreter.attach(logs)
    interpreter.start()
    assert [(m.data["label"], m.data["value"]) for m in logs.seen] == [("outcome", 2)]
    assert (interpreter.running, interpreter.final_state, interpreter.configuration) == (False, "end", [])
    with pytest.raises(ExecutionError, match="already started"):
        interpreter.start()


def test_from_file_reads_data_beside_the_chart(tmp_path: Path) -> None:
    (tmp_path / "limits.txt").write_text("{'force': 45}")
    (tmp_path / "chart.scxml").write_text(f"""<scxml xmlns="{SCXML_NS}" version="1.0" datamodel="python">
      <datamodel><data id="limits" src="file:limits.txt"/></datamodel>
      <state id="s"><transition cond="limits['force'] == 45" target="ok"/></state>
      <final id="ok"/>
    </scxml>""")
    interpreter = Interpreter.from_file(tmp_path / "chart.scxml", session_id="one")
    interpreter.start()
    assert interpreter.final_state == "ok"
    assert interpreter.datamodel["_sessionid"] == "one"


def test_a_chart_that_never_settles_stops_with_a_clear_error() -> None:
    interpreter = session("""
    <state id="a"><transition target="b"/></state>
    <state id="b"><transition target="a"/></state>""")
    with pytest.raises(ExecutionError, match="no stable configuration after 100000 microsteps"):
        interpreter.start()
    assert not interpreter.running


def test_a_hostile_expression_in_a_chart_is_an_execution_error_not_a_hang() -> None:
    interpreter = started("""
    <datamodel><data id="x" expr="0"/></datamodel>
    <state id="s">
      <onentry><assign location="x" expr="10**10**10"/></onentry>
      <transition event="error.execution" target="refused"/>
    </state>
    <state id="refused"/>""")
    assert interpreter.is_active("refused") and interpreter.datamodel["x"] == 0
