"""The Task State Chart and the Specific Process State Charts of the bin-picking task."""

from __future__ import annotations

import pytest
from lxml import etree

from plugnproduce import service
from plugnproduce.codegen import ImplausibleStep, generate_task
from plugnproduce.codegen.outputs import all_charts
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.io.schema import schema_problems
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.interpreter import Interpreter
from tests.codegen.conftest import bind_by_skill, generate

NS = {"s": "http://www.w3.org/2005/07/scxml", "pnp": "http://plugnproduce.org/ontology#"}


@pytest.fixture(scope="module")
def generated(bin_picking_cell, processes):
    return generate("bin-picking", bin_picking_cell, processes)


def test_every_chart_is_valid_w3c_scxml(generated, bin_picking_cell) -> None:
    charts = all_charts(generated, bin_picking_cell, per_device=True)
    assert {c.kind for c in charts} == {"specific", "task", "closed-world", "device-program"}
    for chart in charts:
        assert schema_problems(chart.data, chart.name) == [], chart.name


def test_gripper_region_has_the_mirrored_commands(generated) -> None:
    tree = etree.fromstring(generated.task_chart())
    region = tree.find(".//s:state[@id='s1_gripper']", NS)
    sends = [s.get("event") for s in region.iterfind(".//s:send[@type='xirp']", NS)]
    waits = [t.get("event") for t in region.iterfind(".//s:transition[@event]", NS)]
    assert sends == ["xirp.request.Close"]  # device waits for request Close → controller sends it
    assert waits == ["gripper.xirp.event.gripper_closed"]  # device sends event → controller waits for it
    place = tree.find(".//s:state[@id='s2_gripper']", NS)
    assert [s.get("event") for s in place.iterfind(".//s:send[@type='xirp']", NS)] == ["xirp.request.Open"]


def test_synchronisation_is_kept(generated) -> None:
    tree = etree.fromstring(generated.task_chart())
    close = tree.find(".//s:state[@id='s1_gripper_open']/s:transition", NS)
    assert close.get("cond") == "In('s1_robot_at_part')"


def test_a_region_waits_for_another_once_before_its_first_command_not_again_for_its_devices_answer(
        generated) -> None:
    # the gripper closes once the robot is at the part, then follows its own device: were its wait for
    # gripper_closed also held to In('s1_robot_at_part'), a robot moving on first would leave it waiting for ever
    tree = etree.fromstring(generated.task_chart())
    region = tree.find(".//s:state[@id='s1_gripper']", NS)
    moves = [(t.getparent().get("id"), t.get("event"), t.get("cond")) for t in region.iterfind(".//s:transition", NS)]
    assert moves == [("s1_gripper_open", None, "In('s1_robot_at_part')"),
                     ("s1_gripper_closed_1a", "gripper.xirp.event.gripper_closed", None)]


def test_parameter_values_are_bound_to_the_commands(generated) -> None:
    tree = etree.fromstring(generated.task_chart())
    close = tree.find(".//s:state[@id='s1_gripper_open']//s:send", NS)
    assert [(p.get("name"), p.get("expr")) for p in close] == [("GripForce", "45")]
    move = tree.find(".//s:state[@id='s2_robot_idle']//s:send", NS)
    assert ("TargetPose", "[0.6, -0.2, 0.1, 0, 180, 0]") in [(p.get("name"), p.get("expr")) for p in move]


def test_device_not_in_a_step_stays_where_it_was(generated) -> None:
    tree = etree.fromstring(generated.task_chart())
    stays = tree.find(".//s:state[@id='s2_sensor3d']/s:final", NS)
    assert stays.get("{http://plugnproduce.org/ontology#}deviceState") == "captured"


def test_generation_is_deterministic(bin_picking_cell, processes, generated) -> None:
    again = generate("bin-picking", bin_picking_cell, processes)
    assert [c.data for c in all_charts(again, bin_picking_cell, True)] == [
        c.data for c in all_charts(generated, bin_picking_cell, True)
    ]


def test_implausible_step_is_refused(bin_picking_cell, processes) -> None:
    task = service.task(service.builtin("tasks", "bin-picking-invalid.yaml"))
    with pytest.raises(ImplausibleStep) as err:
        generate_task(task, bin_picking_cell, bind_by_skill(task, bin_picking_cell, processes), processes,
                      service.knowledge().taxonomy)
    assert (err.value.step.index, err.value.device, err.value.state) == (2, "gripper", "closed")


def test_device_program_lists_the_gripper_commands_in_order(generated, bin_picking_cell) -> None:
    program = next(c for c in all_charts(generated, bin_picking_cell, True) if c.name == "bin-picking.gripper.program.scxml")
    sent: list[str] = []

    class Wire:
        def send(self, event, target, type) -> None:  # noqa: A002 - the SCXML name
            sent.append(event.name)

    clock = ManualClock()
    program_run = Interpreter(parse_chart(program.data, program.name), clock=clock, io_processors={"xirp": Wire()})
    program_run.start()
    for request in ["xirp.request.Close", "xirp.request.Open"] * 3:
        program_run.queue(request).execute()
        clock.advance(1.0)
        program_run.execute()
    assert sent == ["xirp.event.gripper_closed", "xirp.event.gripper_opened"] * 3
    assert program_run.final_state == "end"


def test_device_program_writes_each_distinct_path_once(generated, bin_picking_cell) -> None:
    program = next(c for c in all_charts(generated, bin_picking_cell, True) if c.name == "bin-picking.gripper.program.scxml")
    requests = [t.event for s in parse_chart(program.data, program.name).states() for t in getattr(s, "transitions", [])
                if "request" in (t.event or "")]
    assert requests == ["xirp.request.Close", "xirp.request.Open"]
