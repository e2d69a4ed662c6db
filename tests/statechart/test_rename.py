"""Renaming a chart's variables and states in its expressions (for the closed-world chart's device regions)."""

from __future__ import annotations

import pytest

from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.model import Assign, Foreach, If, Send, State, Transition, walk
from plugnproduce.statechart.rename import rename_in, renamed_expression

VARIABLES = {"grips": "g__grips", "pose": "g__pose"}
STATES = {"closing": "g__closing"}


@pytest.mark.parametrize("source, expected", [
    ("grips + 1", "g__grips + 1"),
    ("pose[0] if grips else pose", "g__pose[0] if g__grips else g__pose"),
    ("In('closing') and grips > 0", "In('g__closing') and g__grips > 0"),
    ("In('open')", "In('open')"),  # no state of this chart: as written
    ("_event.data.grips", "_event.data.grips"),  # an attribute is no variable
    ("'grips'", "'grips'"),  # nor is a string
    ("dict(grips=1)", "dict(grips=1)"),  # nor a keyword's name
    ("[grips for grips in pose]", "[g__grips for g__grips in g__pose]"),  # renamed alike: the same meaning
    ("grips +", "grips +"),  # no valid expression: left for the interpreter to report where it is evaluated
])
def test_a_variable_is_renamed_wherever_it_is_read_and_only_there(source: str, expected: str) -> None:
    assert renamed_expression(source, VARIABLES, STATES) == expected


CHART = b"""<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="closing" datamodel="python">
  <datamodel><data id="grips" expr="0"/><data id="pose" expr="[0, 0]"/></datamodel>
  <state id="closing">
    <onentry>
      <assign location="pose[0]" expr="grips"/>
      <if cond="grips &gt; 1"><log expr="pose"/></if>
      <foreach array="pose" item="grips" index="i"><assign location="grips" expr="grips"/></foreach>
      <send event="e" namelist="grips pose i"><param name="grips" expr="grips"/></send>
    </onentry>
    <transition event="done" cond="In('closing') and grips == 0" target="closing"/>
  </state>
</scxml>"""


def test_every_expression_location_and_namelist_of_a_state_follows() -> None:
    state = next(c for c in parse_chart(CHART, "t").children if isinstance(c, State))
    rename_in(state, VARIABLES, STATES)
    nodes = list(walk(state))
    assigns = [(a.location, a.expr) for a in nodes if isinstance(a, Assign)]
    assert assigns == [("g__pose[0]", "g__grips"), ("g__grips", "g__grips")]
    assert next(n for n in nodes if isinstance(n, If)).cond == "g__grips > 1"
    loop = next(n for n in nodes if isinstance(n, Foreach))
    assert (loop.array, loop.item, loop.index) == ("g__pose", "g__grips", "i")
    send = next(n for n in nodes if isinstance(n, Send))
    assert send.namelist == ["g__grips", "g__pose", "i"] and send.params[0].expr == "g__grips"
    assert send.params[0].name == "grips"  # the name the receiver reads stays
    assert next(n for n in nodes if isinstance(n, Transition)).cond == "In('g__closing') and g__grips == 0"
