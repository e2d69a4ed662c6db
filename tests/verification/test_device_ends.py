"""What ``pnp verify`` tells of devices its deadlock and refusal sentences meet less often: a device whose chart has
ended (a top-level final state), a device deep inside a hierarchical chart, and a controller left waiting for two
devices at once. Each program is generated on the cell as shipped and verified on a copy whose device chart was
changed, as a device replaced by a differently behaving one would be."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

from plugnproduce import service
from plugnproduce.statechart.io.reader import parse_chart
from plugnproduce.statechart.runtime.events import EventData
from plugnproduce.verification import verify
from plugnproduce.verification.world import ClosedWorld, Message, Move, Violation
from tests.verification.test_verify import CELL, TASK, D, line_of, seeded_cell

LIBRARIES = Path(__file__).parents[1] / "data" / "libraries"
GRIPPER = (D / "devices" / "gripper.scxml").read_text(encoding="utf-8")
CLOSED = '<state id="closed" pnp:concept="Closed">\n    <transition event="xirp.request.Open" target="opening"/>\n  </state>'
ANSWERS_CLOSED = ('<transition event="motion.done" target="closed">\n      '
                  '<send event="xirp.event.gripper_closed" type="xirp"/>\n    </transition>')


def changed(text: str, old: str, new: str) -> str:
    """``text`` with ``old`` (which must be there) replaced once by ``new``."""
    assert old in text, old
    return text.replace(old, new, 1)


def library_copy(tmp_path: Path, name: str) -> Path:
    return Path(shutil.copytree(LIBRARIES / name, tmp_path / name))


def test_a_device_whose_chart_ended_without_answering_is_a_deadlock_that_names_its_final_state(tmp_path: Path) -> None:
    # the gripper closes into a top-level final state and never reports gripper_closed: its session has ended
    chart = changed(GRIPPER, ANSWERS_CLOSED, '<transition event="motion.done" target="gone"/>')
    chart = changed(chart, "</scxml>", '<final id="gone"/>\n</scxml>')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert result.verdict == "refuted"
    assert result.problem == ("deadlock: the controller waits for gripper.xirp.event.gripper_closed and no device will "
                              "send it (robot in at_pose, gripper in gone, sensor3d in captured, binpicking-pc in "
                              "localized)")
    file = tmp_path / "devices" / "gripper.scxml"
    gone = line_of(file, 'target="gone"')
    assert f"{file}:{gone}: gripper delay of motion.done passes: closing -> gone" in [str(s) for s in result.trace]


def test_a_request_to_a_device_whose_chart_ended_is_refused_in_its_final_state_at_its_line(tmp_path: Path) -> None:
    # the gripper reports gripper_closed and its chart ends in the final state closed: the place step's Open is refused
    chart = changed(GRIPPER, CLOSED, '<final id="closed" pnp:concept="Closed"/>')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert result.verdict == "refuted"
    assert result.problem == ("device gripper in state closed refuses xirp.request.Open: its chart has no "
                              "transition for it there")
    file = tmp_path / "devices" / "gripper.scxml"
    final, closes = line_of(file, '<final id="closed"'), line_of(file, 'event="motion.done" target="closed"')
    assert str(result.trace[-1]) == (f"{file}:{final}: gripper receives xirp.request.Open in state closed, "
                                     "which has no transition for it")
    assert f"{file}:{closes}: gripper delay of motion.done passes: closing -> closed" in [str(s) for s in result.trace]


def test_a_deadlock_names_every_state_a_hierarchical_device_is_in(tmp_path: Path) -> None:
    library = library_copy(tmp_path, "packml-screwing")
    chart = library / "devices" / "packml-screwdriver.scxml"
    chart.write_text(changed(chart.read_text(encoding="utf-8"), '<send event="xirp.event.screw_done" type="xirp"/>',
                             ""), encoding="utf-8")  # it completes the screw but never says so
    task, cell = library / "tasks" / "screw-twice.yaml", library / "cells" / "packml-screwing.yaml"
    result = verify(service.generate(LIBRARIES / "packml-screwing" / "tasks" / "screw-twice.yaml",
                                     LIBRARIES / "packml-screwing" / "cells" / "packml-screwing.yaml").task,
                    service.cell(cell))
    assert result.verdict == "refuted"
    assert result.problem == ("deadlock: the controller waits for packml-screwdriver.xirp.event.screw_done and no "
                              "device will send it (cobot in at_pose, packml-screwdriver in "
                              "Abortable/Operating/Complete)")
    assert result.trace[-1].where == f"{LIBRARIES / 'packml-screwing' / 'tasks' / 'screw-twice.yaml'}:" \
                                     f"{line_of(task, 'command: screw')}"


def test_a_controller_left_waiting_for_two_devices_names_both_events(tmp_path: Path) -> None:
    # the second step moves the robot while the gripper opens: here neither answers
    library = library_copy(tmp_path, "timed-cell")
    robot, gripper = library / "devices" / "tc-robot.scxml", library / "devices" / "tc-gripper.scxml"
    text = robot.read_text(encoding="utf-8")
    at_pose = text.index('<state id="at_pose"')
    robot.write_text(text[:at_pose] + changed(text[at_pose:], 'event="xirp.request.MoveTo" target="moving"',
                                              'event="xirp.request.MoveTo" target="stalled"')
                     .replace("</scxml>", '<state id="stalled" pnp:concept="Moving"/>\n</scxml>'), encoding="utf-8")
    gripper.write_text(changed(gripper.read_text(encoding="utf-8"), '<send event="xirp.event.angle_set" type="xirp"/>',
                               ""), encoding="utf-8")
    shipped = LIBRARIES / "timed-cell"
    generated = service.generate(shipped / "tasks" / "approach-while-opening.yaml",
                                 shipped / "cells" / "timed-cell.yaml").task
    result = verify(generated, service.cell(library / "cells" / "timed-cell.yaml"))
    assert result.verdict == "refuted"
    assert result.problem == ("deadlock: the controller waits for tc-gripper.xirp.event.angle_set or "
                              "tc-robot.xirp.event.motion_done and no device will send it "
                              "(tc-robot in stalled, tc-gripper in open)")


def test_a_program_whose_plan_names_no_step_waits_for_nothing(tmp_path: Path) -> None:
    task, cell = D / "tasks" / "pick-and-place.yaml", service.cell(CELL)
    generated = service.generate(task, cell).task
    chart = generated.task_chart()
    broken = changed(chart.decode(), '<data id="pnp_plan">[1, 2, 0]</data>', '<data id="pnp_plan">[1, 9, 0]</data>')
    result = verify(dataclasses.replace(generated, chart=parse_chart(broken.encode(), "task.scxml")), cell)
    assert result.verdict == "refuted"
    assert result.problem.startswith("deadlock: the controller waits for nothing and no device will send it (")


def test_an_event_a_device_sends_itself_at_once_is_a_move_told_in_the_counterexample(tmp_path: Path) -> None:
    # the gripper closes at once (no delay) and then ends in its final state closed: the place step's Open is refused
    chart = changed(GRIPPER, '<send event="motion.done" delay="120ms"/></onentry>\n    <transition event="motion.done" '
                    'target="closed">', '<send event="motion.done"/></onentry>\n    <transition event="motion.done" '
                    'target="closed">')
    chart = changed(chart, CLOSED, '<final id="closed" pnp:concept="Closed"/>')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert result.problem == ("device gripper in state closed refuses xirp.request.Open: its chart has no "
                              "transition for it there")
    file = tmp_path / "devices" / "gripper.scxml"
    close, closes = line_of(file, 'event="xirp.request.Close"'), line_of(file, 'event="motion.done" target="closed"')
    assert [str(s) for s in result.trace[10:13]] == [
        f"{file}:{close}: gripper receives xirp.request.Close: open -> closing",
        f"{file}:{closes}: gripper takes motion.done: closing -> closed",
        f"{TASK}:6: controller receives gripper.xirp.event.gripper_closed; sends xirp.request.MoveTo to robot"]


def test_a_device_that_answers_at_once_interleaves_with_the_others_as_one_whose_motion_takes_time(
        tmp_path: Path) -> None:
    # the robot moves while the gripper opens; this robot's motion ends at once (an event it sends itself without
    # delay): the gripper may still take its request or its delay before the robot takes that event
    shipped = LIBRARIES / "timed-cell"
    generated = service.generate(shipped / "tasks" / "approach-while-opening.yaml",
                                 shipped / "cells" / "timed-cell.yaml").task
    timed = verify(generated, service.cell(shipped / "cells" / "timed-cell.yaml"))
    library = library_copy(tmp_path, "timed-cell")
    robot = library / "devices" / "tc-robot.scxml"
    robot.write_text(changed(robot.read_text(encoding="utf-8"), '<send id="moving_motion" event="motion.done" '
                             'delay="250ms"/>', '<send id="moving_motion" event="motion.done"/>'), encoding="utf-8")
    at_once = verify(generated, service.cell(library / "cells" / "timed-cell.yaml"))
    assert at_once.verdict == timed.verdict == "proved"
    assert (at_once.states, at_once.transitions) == (timed.states, timed.transitions) == (34, 51)


def test_an_event_a_device_sends_as_it_starts_is_told_as_that_devices(tmp_path: Path) -> None:
    # the gripper (the second device of the cell) says it is ready as it starts; the controller does not wait for it
    chart = changed(GRIPPER, '<state id="open" pnp:concept="Open">', '<state id="open" pnp:concept="Open">\n    '
                    '<onentry><send event="xirp.event.ready" type="xirp"/></onentry>')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert result.verdict == "refuted"
    assert result.problem == ("the controller does not wait for gripper.xirp.event.ready where it is: the run would "
                              "stop with a fault")
    assert [str(s) for s in result.trace] == [
        f"{TASK}:6: controller starts the task; sends upnp.request.Capture to sensor3d",
        f"{TASK}:6: controller receives gripper.xirp.event.ready"]


def test_a_request_a_nested_state_refuses_is_told_at_the_innermost_states_line(tmp_path: Path) -> None:
    # this screwdriver cannot be reset from Complete: the second screw's Reset, sent with its Start, is refused
    shipped = LIBRARIES / "packml-screwing"
    task = shipped / "tasks" / "screw-twice.yaml"
    generated = service.generate(task, shipped / "cells" / "packml-screwing.yaml").task
    library = library_copy(tmp_path, "packml-screwing")
    chart = library / "devices" / "packml-screwdriver.scxml"
    chart.write_text(changed(chart.read_text(encoding="utf-8"), '<state id="Complete" pnp:concept="Fastened">\n        '
                             '<transition event="xirp.request.Reset" target="Idle"/>\n      </state>',
                             '<state id="Complete" pnp:concept="Fastened"/>'), encoding="utf-8")
    result = verify(generated, service.cell(library / "cells" / "packml-screwing.yaml"))
    assert result.problem == ("device packml-screwdriver in state Abortable/Operating/Complete refuses "
                              "xirp.request.Reset: its chart has no transition for it there")
    second, complete = line_of(task, "command: screw") + 2, line_of(chart, '<state id="Complete"')
    assert [str(s) for s in result.trace[-2:]] == [
        f"{task}:{second}: controller receives cobot.xirp.event.motion_done; sends xirp.request.Reset to "
        "packml-screwdriver, xirp.request.Start to packml-screwdriver",
        f"{chart}:{complete}: packml-screwdriver receives xirp.request.Reset in state "
        "Abortable/Operating/Complete, which has no transition for it"]


def test_a_device_of_one_state_refuses_at_that_states_line(tmp_path: Path) -> None:
    # a gripper replaced by one that answers Close at once and stays where it is: the place step's Open is refused
    chart = GRIPPER[:GRIPPER.index('  <state id="open"')] + (
        '  <state id="open" pnp:concept="Open">\n'
        '    <transition event="xirp.request.SetAngle" pnp:accepts="OpeningAngle">'
        '<send event="xirp.event.angle_set" type="xirp"/></transition>\n'
        '    <transition event="xirp.request.Close" pnp:accepts="GripForce">'
        '<send event="xirp.event.gripper_closed" type="xirp"/></transition>\n'
        '  </state>\n</scxml>\n')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    file = tmp_path / "devices" / "gripper.scxml"
    assert str(result.trace[-1]) == (f"{file}:{line_of(file, '<state id=')}: gripper receives xirp.request.Open in "
                                     "state open, which has no transition for it")


def test_a_first_step_that_starts_two_devices_tells_both_requests_as_the_task_starts(tmp_path: Path) -> None:
    shipped = LIBRARIES / "timed-cell"
    task = tmp_path / "open-on-the-way.yaml"
    task.write_text("task: open-on-the-way\nsteps:\n  - command: approach-and-open\n    params: {target_pose: "
                    "[0.40, 0.30, 0.00, 0, 180, 0], speed: 80, opening_angle: 40}\n", encoding="utf-8")
    generated = service.generate(task, shipped / "cells" / "timed-cell.yaml").task
    library = library_copy(tmp_path, "timed-cell")
    gripper = library / "devices" / "tc-gripper.scxml"
    gripper.write_text(changed(gripper.read_text(encoding="utf-8"), '<send event="xirp.event.angle_set" type="xirp"/>',
                               ""), encoding="utf-8")  # it sets the angle but never says so
    result = verify(generated, service.cell(library / "cells" / "timed-cell.yaml"))
    assert result.problem.startswith("deadlock: the controller waits for tc-gripper.xirp.event.angle_set and")
    assert str(result.trace[0]) == (f"{task}:3: controller starts the task; sends xirp.request.MoveTo to tc-robot, "
                                    "xirp.request.SetAngle to tc-gripper")


def test_a_counterexample_in_a_later_round_is_told_at_that_rounds_step(tmp_path: Path) -> None:
    # a gripper that wears out: once opened again it refuses to close, so the second round's bin-pick fails
    chart = changed(GRIPPER, '<transition event="motion.done" target="open">\n      '
                    '<send event="xirp.event.gripper_opened" type="xirp"/>',
                    '<transition event="motion.done" target="worn">\n      '
                    '<send event="xirp.event.gripper_opened" type="xirp"/>')
    chart = changed(chart, "</scxml>", '  <state id="worn" pnp:concept="Open"/>\n</scxml>')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert result.problem == ("device gripper in state worn refuses xirp.request.Close: its chart has no transition "
                              "for it there")
    bin_pick, place = line_of(TASK, "command: bin-pick"), line_of(TASK, "command: place")
    sent = [s for s in result.trace if "; sends xirp.request" in s.text and "to gripper" in s.text]
    assert [(s.where, s.text.rsplit("; sends ", 1)[1]) for s in sent] == [
        (f"{TASK}:{bin_pick}", "xirp.request.Close to gripper"), (f"{TASK}:{place}", "xirp.request.Open to gripper"),
        (f"{TASK}:{bin_pick}", "xirp.request.Close to gripper")]


def test_a_device_chart_that_never_settles_is_refuted_naming_the_device(tmp_path: Path) -> None:
    # on Close this gripper dithers between two states by eventless transitions: its session stops with an error
    chart = changed(GRIPPER, 'event="xirp.request.Close" target="closing"', 'event="xirp.request.Close" target="dither"')
    chart = changed(chart, "</scxml>", '  <state id="dither" pnp:concept="Closing"><transition target="dather"/></state>\n'
                    '  <state id="dather" pnp:concept="Closing"><transition target="dither"/></state>\n</scxml>')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert result.verdict == "refuted"
    assert result.problem == ("device gripper: gripper found no stable configuration after 100000 microsteps: its "
                              "eventless transitions or internal events run in a cycle")
    file = tmp_path / "devices" / "gripper.scxml"
    close = line_of(file, 'target="dither"')
    assert str(result.trace[-1]) == f"{file}:{close}: gripper receives xirp.request.Close: open -> dither"


def test_a_task_chart_that_never_settles_is_refuted_as_the_task_charts_error() -> None:
    task, cell = D / "tasks" / "pick-and-place.yaml", service.cell(CELL)
    generated = service.generate(task, cell).task
    chart = changed(generated.task_chart().decode(), 'cond="pnp_plan[pnp_step] == 0" target="done"',
                    'cond="pnp_plan[pnp_step] == 0" target="next_step"')  # after the last step: round and round
    result = verify(dataclasses.replace(generated, chart=parse_chart(chart.encode(), "task.scxml")), cell)
    assert result.verdict == "refuted"
    assert result.problem == ("the task chart: task-pick-and-place found no stable configuration after 100000 "
                              "microsteps: its eventless transitions or internal events run in a cycle")
    assert str(result.trace[-1]) == f"{task}:{line_of(task, 'command: move-to')}: controller receives " \
                                    "robot.xirp.event.motion_done"


SENSOR = (D / "devices" / "sensor3d.scxml").read_text(encoding="utf-8")


def racing_sensor(tmp_path: Path, answer: str) -> Path:
    """The bin-picking cell with a 3D sensor whose capture ends in one of two ways, whichever of its two delays passes
    first: captured with CaptureDone, or captured with ``answer``; the cell file's path."""
    cell = seeded_cell(tmp_path, (D / "devices" / "gripper.scxml").read_text(encoding="utf-8"))
    (tmp_path / "devices" / "sensor3d.scxml").write_text(changed(
        SENSOR, '    <onentry><send event="capture.done" delay="180ms"/></onentry>',
        '    <onentry><send id="done" event="capture.done" delay="180ms"/>'
        '<send id="dark" event="capture.dark" delay="200ms"/></onentry>\n'
        '    <onexit><cancel sendid="done"/><cancel sendid="dark"/></onexit>\n'
        f'    <transition event="capture.dark" target="captured">{answer}</transition>'), encoding="utf-8")
    return cell


def test_two_answers_that_differ_only_in_their_name_are_both_explored(tmp_path: Path) -> None:
    # either way the sensor ends in captured with nothing left to do: only the event on its way tells them apart
    cell = racing_sensor(tmp_path, '<send event="upnp.event.TooDark" type="upnp"/>')
    result = verify(service.generate(TASK, CELL).task, service.cell(cell))
    assert result.verdict == "refuted"
    assert result.problem == ("the controller does not wait for sensor3d.upnp.event.TooDark where it is: the run "
                              "would stop with a fault")


def test_two_answers_that_differ_only_in_their_data_are_two_configurations(tmp_path: Path) -> None:
    cell = racing_sensor(tmp_path, '<send event="upnp.event.CaptureDone" type="upnp"><param name="Quality" '
                                   "expr=\"'dark'\"/></send>")
    result = verify(service.generate(TASK, CELL).task, service.cell(cell))
    assert result.verdict == "proved"
    # three more configurations and six more moves than with the shipped sensor (73, 75): in each of the three rounds,
    # the dark answer on its way is a configuration of its own, reached by the dark delay passing and left by the
    # controller receiving it
    assert (result.states, result.transitions) == (76, 81)


def test_a_device_chart_that_reads_a_requests_arguments_is_given_them(tmp_path: Path) -> None:
    # this gripper only closes with more than 40 N (less would not hold the part): 45 N is proved, 35 N refused
    chart = changed(GRIPPER, 'event="xirp.request.Close" target="closing"',
                    'event="xirp.request.Close" cond="_event.data[\'GripForce\'] &gt; 40" target="closing"')
    cell = service.cell(seeded_cell(tmp_path, chart))
    assert verify(service.generate(TASK, CELL).task, cell).verdict == "proved"
    gentle = tmp_path / "gentle.yaml"
    gentle.write_text(changed(TASK.read_text(encoding="utf-8"), "grip_force: 45", "grip_force: 35"), encoding="utf-8")
    result = verify(service.generate(gentle, CELL).task, cell)
    assert result.problem == ("device gripper in state open refuses xirp.request.Close: its chart has no transition "
                              "for it there")


def test_a_request_with_two_problems_names_both(tmp_path: Path) -> None:
    # a gripper whose Close takes an opening angle too, sent a Close with neither argument
    chart = changed(GRIPPER, 'pnp:accepts="GripForce"', 'pnp:accepts="GripForce OpeningAngle"')
    cell = service.cell(seeded_cell(tmp_path, chart))
    world = ClosedWorld(service.generate(TASK, CELL).task, cell)
    initial, _ = world.start()
    requests = list(initial.requests)
    requests[world.devices_index("gripper")] = (Message("xirp.request.Close", EventData({})),)
    sent = dataclasses.replace(initial, requests=tuple(requests))
    _, violation = world.apply(sent, Move("request", "gripper", name="xirp.request.Close"))
    assert violation == Violation("argument", "device gripper: xirp.request.Close lacks the argument GripForce that "
                                              "its transition accepts; lacks the argument OpeningAngle that its "
                                              "transition accepts")


def test_a_localizer_that_reports_no_outcome_fails_a_task_that_branches_on_it(tmp_path: Path) -> None:
    # the task goes home when the bin is empty: it reads the outcome the localizer's answer reports, and this one
    # reports none (the run's task chart then stops in failed)
    cell = seeded_cell(tmp_path, GRIPPER)
    pc = tmp_path / "devices" / "binpicking-pc.scxml"
    pc.write_text(changed(pc.read_text(encoding="utf-8"), '<param name="outcome" expr="outcome"/>', ""),
                  encoding="utf-8")
    then_home = D / "tasks" / "bin-picking-then-home.yaml"
    result = verify(service.generate(then_home, CELL).task, service.cell(cell))
    assert result.problem == "the task ends in failed, not done"
    assert result.trace[-1].text == "controller receives binpicking-pc.upnp.event.PartLocalized"


def test_a_transition_written_for_two_requests_takes_either(tmp_path: Path) -> None:
    # the gripper opens on Open or Release, one transition for both (a request of no arguments)
    chart = changed(GRIPPER, 'event="xirp.request.Open" target="opening"',
                    'event="xirp.request.Open xirp.request.Release" target="opening"')
    result = verify(service.generate(TASK, CELL).task, service.cell(seeded_cell(tmp_path, chart)))
    assert (result.verdict, result.states, result.transitions) == ("proved", 73, 75)
