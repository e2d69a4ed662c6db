"""A task chart that never settles: an eventless transition without a target, taken again and again in one macrostep.

Each time it is taken it asks the robot to move. Before, each request queued behind all the earlier ones (a copy of
them all per request): the run spent minutes and gigabytes before the interpreter's microstep bound was reached, and
did not stop on SIGTERM meanwhile. Now the run ends at once as a fault of the chart, in one line, with nothing sent to
the robot: the executor refuses to queue more than MAX_UNANSWERED requests to a device, and the interpreter's bound
ends the macrostep.
"""

from __future__ import annotations

from pathlib import Path

from plugnproduce import controller, service
from plugnproduce.discovery import LiveCell
from plugnproduce.executor.journal import read_journal
from plugnproduce.executor.run import MAX_UNANSWERED, TaskRun
from plugnproduce.protocols import upnp
from plugnproduce.sim.cell import SimulatedCell
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.runtime.interpreter import MAX_MICROSTEPS

CELL = service.builtin("cells", "bin-picking.yaml")
MOVE = """task: spin
steps:
  - command: move-to
    params: {target_pose: [0.30, 0.00, 0.50, 0, 180, 0], speed: 50}
"""
SPINNING = """<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:pnp="http://plugnproduce.org/ontology#"
       version="1.0" name="task-spin" initial="task" datamodel="python">
  <datamodel>
    <data id="pnp_step" expr="0"/>
  </datamodel>
  <state id="task" initial="s1">
    <transition event="timeout error" target="failed"/>
    <parallel id="s1" pnp:command="move-to">
      <transition event="done.state.s1" target="done"/>
      <state id="s1_robot" initial="s1_robot_idle" pnp:device="robot" pnp:role="robot">
        <state id="s1_robot_idle" pnp:concept="Idle" pnp:deviceState="home">
          <transition>  <!-- no target, no event: enabled again at once -->
            <send event="xirp.request.MoveTo" target="robot" type="xirp">
              <param name="TargetPose" expr="[0.3, 0.0, 0.5, 0, 180, 0]"/>
              <param name="Speed" expr="50"/>
            </send>
          </transition>
        </state>
      </state>
    </parallel>
  </state>
  <final id="done"/>
  <final id="failed"/>
</scxml>
"""


async def test_a_chart_that_never_settles_fails_the_run_in_one_line_and_sends_nothing(tmp_path: Path,
                                                                                      taxonomy) -> None:
    task = tmp_path / "spin.yaml"
    task.write_text(MOVE, encoding="utf-8")
    cell = service.cell(CELL)
    generated = service.generate(task, cell).task
    generated.chart = parse_chart(SPINNING.encode(), "spin.task.scxml")
    network = upnp.private_network()
    async with SimulatedCell(cell, network=network) as sim, LiveCell(taxonomy, network=network) as live:
        devices = await controller.find_devices(live, [d.id for d in cell.devices],
                                                controller.SIMULATED_DISCOVERY_SECONDS)
        report = await TaskRun(generated, devices, tmp_path / "run.jsonl").run()
        robot_after = sim.devices["robot"].state
    assert report.outcome == "failed"
    assert report.fault is not None
    assert (report.fault.kind, report.fault.step, report.fault.device, report.fault.request) == (
        "chart", 1, "robot", "MoveTo")
    assert report.fault.message == (f"task-spin queued {MAX_UNANSWERED} requests to robot without waiting for one to "
                                    "be answered: its eventless transitions send in a cycle")
    run = read_journal(report.journal)
    assert [(r["fault"], r["message"], r["first"]) for r in run.of_kind("fault")] == [
        ("chart", report.fault.message, True),  # then the interpreter's own bound ends the macrostep
        ("chart", f"task-spin found no stable configuration after {MAX_MICROSTEPS} microsteps: its eventless "
                  "transitions or internal events run in a cycle", False)]
    assert list(run.of_kind("command")) == []  # not one of the queued MoveTo requests went out
    assert robot_after == "home"
