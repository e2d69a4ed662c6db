"""What descriptions lift from their charts: read once by the one SCXML reader, carried as a model."""

from __future__ import annotations

import pytest

from plugnproduce.description.charts import device_chart, process_regions
from plugnproduce.description.loader import load_device, load_process
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import concept, parse_chart, read_chart

D = descriptions_path()


def test_a_device_description_carries_its_parsed_chart(taxonomy: Taxonomy) -> None:
    gripper = load_device(D / "devices" / "gripper.ttl", taxonomy)
    assert gripper.chart == read_chart(gripper.chart_file)
    closed = gripper.chart.find("closed")
    assert closed is not None and concept(closed) == "Closed"


def test_a_process_description_carries_its_parsed_chart(taxonomy: Taxonomy) -> None:
    pick = load_process(D / "processes" / "pick.ttl")
    assert pick.chart == read_chart(pick.chart_file)
    assert set(process_regions(pick.chart, pick.chart_file)) == {r.name for r in pick.roles}


def test_a_device_chart_with_a_parallel_state_is_refused_with_its_line() -> None:
    text = b"""<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="a">
  <state id="a">
    <parallel id="p"><state id="p1"/><state id="p2"/></parallel>
  </state>
</scxml>"""
    with pytest.raises(DescriptionError, match="has no <parallel>: a device is in one state at a time") as err:
        device_chart(parse_chart(text, "nested.scxml"), "nested.scxml")
    assert str(err.value).startswith("nested.scxml:3:")
