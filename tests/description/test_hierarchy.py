"""Device State Charts with compound states: the states a device can be in and the transitions it takes from
each, as W3C SCXML gives them (the PackML-style screwdriver of the packml-screwing library, and small charts)."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.charts import device_chart
from plugnproduce.description.model import Command, DeviceDescription
from plugnproduce.description.paths import find_path
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.statechart import parse_chart

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "packml-screwing"
PNP = "http://plugnproduce.org/ontology#"
PACKML = "http://example.org/packml#"


@pytest.fixture(scope="module")
def screwdriver() -> DeviceDescription:
    return service.cell(LIBRARY / "cells" / "packml-screwing.yaml").device("packml-screwdriver")


@pytest.fixture(scope="module")
def ours() -> Taxonomy:
    """The taxonomy with the library's PackML state concepts."""
    return service.knowledge((LIBRARY,)).taxonomy


def _chart(body: str) -> bytes:
    return (f'<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:pnp="http://plugnproduce.org/ontology#" '
            f'version="1.0">{body}</scxml>').encode()


def test_the_states_a_device_can_be_in_are_the_atomic_ones_and_it_starts_in_the_initial_leaf(
        screwdriver: DeviceDescription) -> None:
    assert [s.id for s in screwdriver.states] == ["Idle", "Starting", "Execute", "Completing", "Held", "Complete",
                                                  "Stopping", "Stopped", "Aborting", "Aborted"]
    assert [s.id for s in screwdriver.compounds] == ["Abortable", "Operating", "Running"]
    assert screwdriver.initial == "Idle"  # scxml → Abortable → Operating → Idle, by their initial attributes


def test_a_state_inside_a_compound_has_its_own_concept_and_those_around_it(screwdriver: DeviceDescription) -> None:
    execute = screwdriver.state("Execute")
    assert execute.concept == PACKML + "Execute"
    assert execute.every_concept == (PACKML + "Execute", PNP + "Screwing")
    assert execute.within == ("Abortable", "Operating", "Running")


def test_a_superstate_abort_is_taken_from_every_state_inside_it_however_deep(screwdriver: DeviceDescription) -> None:
    for state in ("Idle", "Starting", "Execute", "Completing", "Held", "Complete", "Stopping", "Stopped"):
        stop = screwdriver.stop_from(state)
        assert stop is not None and stop.request == Command("xirp", "request", "Abort"), state
        assert (stop.target, stop.origin) == ("Aborting", "Abortable")
    assert screwdriver.stop_from("Aborting") is None and screwdriver.stop_from("Aborted") is None


def test_stop_applies_to_the_operating_states_only(screwdriver: DeviceDescription) -> None:
    stops = {t.source for t in screwdriver.transitions if t.event == "xirp.request.Stop"}
    assert stops == {"Idle", "Starting", "Execute", "Completing", "Held", "Complete"}
    assert {t.target for t in screwdriver.transitions if t.event == "xirp.request.Stop"} == {"Stopping"}


def test_entering_a_compound_state_enters_its_initial_child(screwdriver: DeviceDescription) -> None:
    start = next(t for t in screwdriver.transitions if t.event == "xirp.request.Start")
    assert (start.source, start.target, start.origin) == ("Idle", "Starting", "Idle")


def test_path_search_goes_through_the_compound_states(screwdriver: DeviceDescription, ours: Taxonomy) -> None:
    to_screwing = find_path(screwdriver, "Complete", PNP + "Screwing", ours)
    assert [(t.source, t.event, t.target) for t in to_screwing.steps] == [
        ("Complete", "xirp.request.Reset", "Idle"), ("Idle", "xirp.request.Start", "Starting")]
    to_fastened = find_path(screwdriver, "Starting", PNP + "Fastened", ours)
    assert [t.target for t in to_fastened.steps] == ["Execute", "Completing", "Complete"]
    assert to_fastened.steps[-1].sends == (Command("xirp", "event", "screw_done"),)
    from_aborted = find_path(screwdriver, "Aborted", PNP + "ToolIdle", ours)
    assert [t.event for t in from_aborted.steps] == ["xirp.request.Clear", "xirp.request.Reset"]


def test_a_transition_sends_what_the_exited_and_entered_states_send_in_scxml_order() -> None:
    chart = parse_chart(_chart("""
  <state id="outer" initial="a">
    <onexit><send event="xirp.event.left_outer" type="xirp"/></onexit>
    <state id="a">
      <onexit><send event="xirp.event.left_a" type="xirp"/></onexit>
      <transition event="xirp.request.Go" target="there"><send event="xirp.event.going" type="xirp"/></transition>
    </state>
  </state>
  <state id="there">
    <onentry><send event="xirp.event.in_there" type="xirp"/></onentry>
    <initial><transition target="deep"><send event="xirp.event.by_initial" type="xirp"/></transition></initial>
    <state id="deep"><onentry><send event="xirp.event.in_deep" type="xirp"/></onentry></state>
  </state>"""), "order.scxml")
    (go,) = device_chart(chart, "order.scxml").transitions
    assert (go.source, go.target) == ("a", "deep")
    assert [c.name for c in go.sends] == ["left_a", "left_outer", "going", "in_there", "by_initial", "in_deep"]


def test_an_inner_transition_on_the_same_event_wins_over_the_superstates() -> None:
    chart = parse_chart(_chart("""
  <state id="outer" initial="a">
    <transition event="xirp.request.Stop" target="stopped"/>
    <state id="a"><transition event="xirp.request.Stop" target="b"/></state>
    <state id="b"><transition event="xirp.request.Stop" cond="False" target="a"/></state>
  </state>
  <state id="stopped"/>"""), "shadow.scxml")
    lifted = device_chart(chart, "shadow.scxml")
    stops = sorted((t.source, t.target) for t in lifted.transitions if t.event == "xirp.request.Stop")
    # a's own Stop is always taken first; b's is conditional, so the superstate's may still be taken
    assert stops == [("a", "b"), ("b", "a"), ("b", "stopped")]
    assert lifted.initial == "a"


def test_a_targetless_superstate_transition_stays_in_the_state_it_is_taken_from() -> None:
    chart = parse_chart(_chart("""
  <state id="outer"><transition event="xirp.request.Ping"><send event="xirp.event.pong" type="xirp"/></transition>
    <state id="a"/><state id="b"/>
  </state>"""), "ping.scxml")
    pings = device_chart(chart, "ping.scxml").transitions
    assert [(t.source, t.target, t.origin) for t in pings] == [("a", "a", "outer"), ("b", "b", "outer")]


def test_a_chart_whose_superstate_transitions_multiply_beyond_the_limit_is_refused_at_once() -> None:
    """400 states inside a superstate with 300 transitions would take 120,000: refused before any is built."""
    leaves = "".join(f'<state id="s{i}"/>' for i in range(400))
    moves = "".join(f'<transition event="xirp.request.R{i}" target="s0"/>' for i in range(300))
    chart = parse_chart(_chart(f'<state id="outer">{moves}{leaves}</state>'), "wide.scxml")
    with pytest.raises(DescriptionError, match="take 120000 transitions, counting each compound state's once for "
                                               "every state inside it; at most 100000 are accepted") as err:
        device_chart(chart, "wide.scxml")
    assert str(err.value).startswith("wide.scxml:1:")


def test_a_superstate_transition_on_an_event_prefix_is_shadowed_by_an_inner_one() -> None:
    """SCXML event descriptors match by prefix: an inner ``xirp.request`` takes every request first."""
    chart = parse_chart(_chart("""
  <state id="outer"><transition event="xirp.request.Stop" target="b"/>
    <state id="a"><transition event="xirp.request" target="a"/></state><state id="b"/>
  </state>"""), "prefix.scxml")
    lifted = device_chart(chart, "prefix.scxml").transitions
    assert [(t.source, t.event, t.target) for t in lifted] == [("a", "xirp.request", "a"),
                                                              ("b", "xirp.request.Stop", "b")]


@pytest.mark.parametrize(("body", "message"), [
    ('<state id="a"><state id="b"><state id="a"/></state></state>', "state id 'a' is used twice"),  # the reader
    ("<state><state/></state>", "two states of the chart have no id"),
])
def test_a_state_id_twice_is_refused_not_looped_on(body: str, message: str) -> None:
    with pytest.raises(DescriptionError, match=message):
        device_chart(parse_chart(_chart(body), "twice.scxml"), "twice.scxml")


def test_a_chart_whose_lifted_transitions_would_send_too_many_events_is_refused() -> None:
    """600 states inside a superstate whose one transition enters a state sending 2,000 events on entry: 1.2 million
    events lifted, beyond the bound, refused instead of built."""
    leaves = "".join(f'<state id="s{i}"/>' for i in range(600))
    sends = "".join(f'<send event="xirp.event.e{i}" type="xirp"/>' for i in range(2000))
    chart = parse_chart(_chart(f'<state id="outer"><transition event="xirp.request.Go" target="big"/>{leaves}</state>'
                               f'<state id="big"><onentry>{sends}</onentry></state>'), "loud.scxml")
    with pytest.raises(DescriptionError, match="send more than 1000000 events in all"):
        device_chart(chart, "loud.scxml")
