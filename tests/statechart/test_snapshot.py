"""Snapshots of a session: put back, it behaves as when taken (what verification relies on)."""

from __future__ import annotations

from collections.abc import Hashable

from plugnproduce.statechart import SCXML_NS, parse_chart
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.statechart.runtime.snapshot import assigned_variables, fire, restore, take

NAPPING = f"""<scxml xmlns="{SCXML_NS}" version="1.0" datamodel="python" initial="awake">
  <datamodel><data id="naps" expr="0"/><data id="name" expr="'gripper'"/></datamodel>
  <state id="awake">
    <onentry><send id="nap" event="tired" delay="30s"/><send event="yawn" delay="1s"/></onentry>
    <onexit><cancel sendid="nap"/></onexit>
    <transition event="work" target="working"/>
    <transition event="tired" target="asleep"><assign location="naps" expr="naps + 1"/></transition>
  </state>
  <state id="working"><transition event="done" target="awake"/></state>
  <state id="asleep"><transition event="wake" target="awake"/></state>
</scxml>"""


def napping() -> Interpreter:
    session = Interpreter(parse_chart(NAPPING.encode(), "napping"), clock=ManualClock())
    session.start()
    return session


def test_only_assigned_variables_are_kept() -> None:
    assert assigned_variables(napping()) == ("naps",)


def test_a_restored_session_cancels_a_named_delayed_send_it_had_when_taken() -> None:
    session = napping()
    variables = assigned_variables(session)
    awake = take(session, variables)
    session.queue("work").execute_once()
    restore(session, awake, variables)
    assert session.configuration == ["awake"]
    session.queue("work").execute_once()
    assert [p.event.name for p in take(session, variables).delayed] == ["yawn"]  # the nap was cancelled


def test_firing_a_delayed_send_moves_the_session_whatever_its_delay() -> None:
    session = napping()
    variables = assigned_variables(session)
    awake = take(session, variables)
    nap = next(p for p in awake.delayed if p.event.name == "tired")
    fire(session, nap)
    assert session.configuration == ["asleep"] and session.datamodel["naps"] == 1
    restore(session, awake, variables)
    assert session.configuration == ["awake"] and session.datamodel["naps"] == 0


def test_the_same_configuration_reached_two_ways_has_the_same_key() -> None:
    session = napping()
    variables = assigned_variables(session)

    def yawned() -> Hashable:
        for pending in [p for p in take(session, variables).delayed if p.event.name == "yawn"]:
            fire(session, pending)
        return take(session, variables).key

    first = yawned()
    session.queue("work").execute_once()
    session.queue("done").execute_once()  # awake again: a new nap, and a yawn with an id the session made up
    assert yawned() == first
    fire(session, next(p for p in take(session, variables).delayed if p.event.name == "tired"))
    assert take(session, variables).key != first
