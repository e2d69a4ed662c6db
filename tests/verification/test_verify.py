"""``pnp verify`` as a user meets it: proofs of the shipped tasks, a seeded deadlock found with its
description lines, a budget that runs out, and ``pnp generate`` refusing a refuted program."""

from __future__ import annotations

import dataclasses
import json
import shutil
import time
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from plugnproduce import controller, service
from plugnproduce.cli import app
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart.io.reader import parse_chart
from plugnproduce.verification import verify
from plugnproduce.verification.arguments import argument_problems

runner = CliRunner()
D = descriptions_path()
TASK, CELL = D / "tasks" / "bin-picking.yaml", D / "cells" / "bin-picking.yaml"
LIBRARIES = Path(__file__).parent.parent / "data" / "libraries"

NAP = """  <state id="open" pnp:concept="Open">
    <onentry><send id="nap" event="idle.timeout" delay="120s"/></onentry>
    <onexit><cancel sendid="nap"/></onexit>
    <transition event="idle.timeout" target="standby"/>"""
STANDBY = """  <state id="standby" pnp:concept="Open">
    <transition event="xirp.request.Wake" target="open"/>
  </state>
</scxml>"""
"""A gripper that goes to standby after 120 s open and then refuses Close until woken: a deadlock only
the interleavings where its timer passes before the robot reaches the part can hit."""


def seeded_cell(tmp_path: Path, chart: str) -> Path:
    """A copy of the bin-picking cell whose gripper chart is ``chart``; the cell file's path."""
    (tmp_path / "devices").mkdir(parents=True)
    (tmp_path / "cells").mkdir()
    for name in ("robot", "gripper", "sensor3d", "binpicking-pc"):
        for ext in ("ttl", "scxml"):
            shutil.copy(D / "devices" / f"{name}.{ext}", tmp_path / "devices")
    (tmp_path / "devices" / "gripper.scxml").write_text(chart, encoding="utf-8")
    cell = tmp_path / "cells" / "bin-picking.yaml"
    cell.write_text(CELL.read_text(encoding="utf-8"), encoding="utf-8")
    return cell


def verify_json(*args: str) -> tuple[int, dict[str, Any]]:
    """``pnp verify ARGS --json``: its exit code and answer, whose seconds must lie within the call."""
    began = time.perf_counter()
    result = runner.invoke(app, ["verify", *args, "--json"])
    elapsed = time.perf_counter() - began
    answer = json.loads(result.stdout)
    assert 0 <= answer["seconds"] <= round(elapsed, 3) + 0.001, (answer["seconds"], elapsed)
    return result.exit_code, answer


def napping_gripper() -> str:
    chart = (D / "devices" / "gripper.scxml").read_text(encoding="utf-8")
    return chart.replace('  <state id="open" pnp:concept="Open">', NAP).replace("</scxml>", STANDBY)


def test_the_bin_picking_task_is_proved_and_the_state_count_reported() -> None:
    code, answer = verify_json(str(TASK), "--cell", str(CELL))
    assert code == 0 and answer["verdict"] == "proved" and answer["trace"] == []
    # the interleavings of the shipped cell's four devices over three rounds, each configuration counted once: a
    # change in what may happen next, or in what tells two configurations apart, changes these
    assert (answer["states"], answer["transitions"]) == (73, 75)


def test_a_deadlock_only_some_interleavings_hit_is_refuted_with_description_lines(tmp_path: Path) -> None:
    cell = seeded_cell(tmp_path, napping_gripper())
    result = runner.invoke(app, ["verify", str(TASK), "--cell", str(cell)])
    assert result.exit_code == 1, result.output
    lines = result.stdout.splitlines()
    assert "refuted" in lines[0]
    assert "device gripper in state standby refuses xirp.request.Close" in lines[1]
    chart = tmp_path / "devices" / "gripper.scxml"
    standby_line = chart.read_text(encoding="utf-8").splitlines().index(STANDBY.splitlines()[0]) + 1
    nap_line = next(i for i, t in enumerate(chart.read_text(encoding="utf-8").splitlines(), 1)
                    if 'event="idle.timeout" target="standby"' in t)
    steps = [line for line in lines if line.startswith("  ")]
    assert any(f"{chart}:{nap_line}: gripper delay of idle.timeout passes" in s for s in steps)
    assert steps[-1].endswith("which has no transition for it") and f"{chart}:{standby_line}:" in steps[-1]
    assert any(f"{TASK}:6: controller" in s for s in steps)  # the bin-pick step of the task file


async def test_the_seeded_deadlock_is_not_hit_by_a_simulated_run(tmp_path: Path) -> None:
    cell = seeded_cell(tmp_path, napping_gripper())
    report = await controller.run_task(TASK, cell, simulate=True, journal=tmp_path / "run.jsonl")
    assert report.outcome == "succeeded", report.fault


def test_the_counterexample_is_the_shortest(tmp_path: Path) -> None:
    cell = seeded_cell(tmp_path, napping_gripper())
    code, answer = verify_json(str(TASK), "--cell", str(cell))
    assert (answer["states"], answer["transitions"]) == (21, 32)  # explored before the refusal was found
    assert code == 1 and answer["trace"][-1]["step"] == ("gripper receives xirp.request.Close in state standby, "
                                                         "which has no transition for it")
    result = service.verify(TASK, cell)
    # After the start, the one run reaches the gripper's Close at its 10th move (sensor, localizer and robot
    # each take a request, their delay and their answer back); the nap is one move more: none is shorter.
    assert result.trace[-1].text == ("gripper receives xirp.request.Close in state standby, "
                                     "which has no transition for it")
    assert len(result.trace) == 1 + 11


def line_of(path: Path, text: str) -> int:
    """The first line of ``path`` that holds ``text``."""
    return next(i for i, t in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if text in t)


def test_the_counterexample_tells_each_move_at_the_line_it_comes_from(tmp_path: Path) -> None:
    cell = seeded_cell(tmp_path, napping_gripper())
    step = (TASK, "command: bin-pick")
    expected = [  # (file, a text of the line the move comes from, what the move does)
        (*step, "controller starts the task; sends upnp.request.Capture to sensor3d"),
        ("gripper", 'target="standby"', "gripper delay of idle.timeout passes: open -> standby"),
        ("sensor3d", "upnp.request.Capture", "sensor3d receives upnp.request.Capture: ready -> capturing"),
        ("sensor3d", 'event="capture.done" target', "sensor3d delay of capture.done passes: capturing -> captured"),
        (*step, "controller receives sensor3d.upnp.event.CaptureDone; sends upnp.request.Localize to binpicking-pc"),
        ("binpicking-pc", "upnp.request.Localize", "binpicking-pc receives upnp.request.Localize: ready -> localizing"),
        ("binpicking-pc", 'event="localize.done" target',
         "binpicking-pc delay of localize.done passes: localizing -> localized"),
        (*step, "controller receives binpicking-pc.upnp.event.PartLocalized reporting PartFound; "
                "sends xirp.request.MoveTo to robot"),
        ("robot", "xirp.request.MoveTo", "robot receives xirp.request.MoveTo: home -> moving"),
        ("robot", 'event="motion.done" target', "robot delay of motion.done passes: moving -> at_pose"),
        (*step, "controller receives robot.xirp.event.motion_done; sends xirp.request.Close to gripper"),
        ("gripper", '<state id="standby"',
         "gripper receives xirp.request.Close in state standby, which has no transition for it")]
    files = [f if isinstance(f, Path) else tmp_path / "devices" / f"{f}.scxml" for f, _, _ in expected]
    assert [str(s) for s in service.verify(TASK, cell).trace] == [
        f"{file}:{line_of(file, text)}: {move}" for file, (_, text, move) in zip(files, expected, strict=True)]


def test_a_device_that_never_answers_is_a_deadlock_at_the_step_that_waits(tmp_path: Path) -> None:
    chart = (D / "devices" / "gripper.scxml").read_text(encoding="utf-8").replace(
        '<onentry><send event="motion.done" delay="120ms"/></onentry>\n    <transition event="motion.done" '
        'target="closed">', '<transition event="motion.done" target="closed">', 1)
    code, answer = verify_json(str(TASK), "--cell", str(seeded_cell(tmp_path, chart)))
    assert code == 1 and answer["problem"] == (
        "deadlock: the controller waits for gripper.xirp.event.gripper_closed and no device will send it "
        "(robot in at_pose, gripper in closing, sensor3d in captured, binpicking-pc in localized)")
    assert answer["trace"][-1]["where"] == f"{TASK}:6" and answer["trace"][-1]["step"].startswith("deadlock")


def test_a_request_missing_an_argument_the_device_takes_is_refused_before_any_program_is_made(tmp_path: Path) -> None:
    chart = (D / "devices" / "gripper.scxml").read_text(encoding="utf-8").replace(
        'pnp:accepts="GripForce"', 'pnp:accepts="GripForce OpeningAngle"')
    result = runner.invoke(app, ["verify", str(TASK), "--cell", str(seeded_cell(tmp_path, chart))])
    assert result.exit_code == 1, result.output
    assert "its request Close needs the argument opening angle" in result.stderr


def test_the_arguments_a_program_sends_are_held_to_the_devices_terms() -> None:
    gripper = service.knowledge().device("gripper")
    close = next(t for t in gripper.transitions if t.request and t.request.name == "Close")
    force = close.accepts[0]
    limit = gripper.argument("Close", force).maximum
    assert limit is not None
    assert argument_problems(gripper, close, {}) == ["lacks the argument GripForce that its transition accepts"]
    assert argument_problems(gripper, close, {"GripForce": limit}) == []
    (too_much,) = argument_problems(gripper, close, {"GripForce": limit + 1})
    assert too_much == f"argument GripForce is {limit + 1!r}, beyond the device's contract: it takes at most {limit:g} N; " \
                       f"the value is {limit + 1:g} N"
    assert argument_problems(gripper, close, {"GripForce": float("nan")}) == [
        "argument GripForce is nan, not a finite value"]
    robot = service.knowledge().device("robot")
    move = next(t for t in robot.transitions if t.request and t.request.name == "MoveTo")
    assert argument_problems(robot, move, {"TargetPose": [0.4, 0, float("nan"), 0, 180, 0], "Speed": 50}) == [
        "argument TargetPose is [0.4, 0, nan, 0, 180, 0], not a finite value"]


def test_a_value_the_process_takes_but_the_device_does_not_is_refuted_as_the_run_would_refuse_it(
        tmp_path: Path) -> None:
    # the process's grip_force is a decimal, this gripper's Close takes a whole number of newtons: the executor
    # refuses to send 45.5 (a contract fault at step 1). The check tells of it in the task; a program that sends
    # it all the same is never called proved
    cell = seeded_cell(tmp_path, (D / "devices" / "gripper.scxml").read_text(encoding="utf-8"))
    description = tmp_path / "devices" / "gripper.ttl"
    description.write_text(description.read_text(encoding="utf-8").replace(
        "pnp:quantity pnp:GripForce ;\n    pnp:datatype xsd:decimal ;",
        "pnp:quantity pnp:GripForce ;\n    pnp:datatype xsd:integer ;"), encoding="utf-8")
    task = tmp_path / "whole-newtons.yaml"
    task.write_text(TASK.read_text(encoding="utf-8").replace("grip_force: 45", "grip_force: 45.5"), encoding="utf-8")
    (finding,) = service.check(task, cell).problems
    assert finding.kind == "device_limit" and finding.text.endswith("takes a whole number; the value is 45.5")
    generated = service.generate(TASK, cell).task  # 45 N: plausible; then made to send 45.5
    chart = generated.task_chart().replace(b'name="GripForce" expr="45"', b'name="GripForce" expr="45.5"')
    assert chart != generated.task_chart()
    result = verify(dataclasses.replace(generated, chart=parse_chart(chart, "task.scxml")), service.cell(cell))
    assert result.verdict == "refuted"
    assert result.problem == ("device gripper: xirp.request.Close argument GripForce is 45.5, beyond the device's "
                              "contract: it takes a whole number; the value is 45.5")


def test_a_program_that_fails_as_it_starts_is_refuted_at_its_first_step_with_no_move() -> None:
    task, cell = D / "tasks" / "pick-and-place.yaml", service.cell(CELL)
    generated = service.generate(task, cell).task
    chart = generated.task_chart().replace(b'<data id="pnp_plan">[1, 2, 0]</data>', b'<data id="pnp_plan">[]</data>')
    assert chart != generated.task_chart()  # its first choice of step reads past the plan: error, then failed
    began = time.perf_counter()
    result = verify(dataclasses.replace(generated, chart=parse_chart(chart, "task.scxml")), cell)
    assert 0 <= result.seconds <= time.perf_counter() - began  # the time it reports is a part of the call's
    assert (result.verdict, result.states, result.transitions) == ("refuted", 1, 0)
    assert result.problem == "the task ends in failed, not done"
    assert [str(s) for s in result.trace] == [f"{task}:{line_of(task, 'command: pick-and-place')}: "
                                               "controller starts the task"]
    assert result.lines()[0].startswith("task pick-and-place on cell bin-picking: refuted (1 states, 0 transitions, ")


def test_a_budget_too_small_is_inconclusive_not_a_hang() -> None:
    result = runner.invoke(app, ["verify", str(TASK), "--cell", str(CELL), "--max-states", "10"])
    assert result.exit_code == 3, result.output
    assert "inconclusive" in result.stdout and "budget of 10 states ran out" in result.stdout


def test_a_budget_of_exactly_the_states_a_proof_needs_proves_it_and_one_state_less_does_not() -> None:
    needed = verify_json(str(TASK), "--cell", str(CELL))[1]["states"]
    code, exactly = verify_json(str(TASK), "--cell", str(CELL), "--max-states", str(needed))
    assert code == 0 and exactly["verdict"] == "proved"
    code, answer = verify_json(str(TASK), "--cell", str(CELL), "--max-states", str(needed - 1))
    assert code == 3
    assert answer["problem"] == (f"the budget of {needed - 1} states ran out before every interleaving was explored")
    assert answer["states"] == needed - 1 and answer["trace"] == []
    assert answer["transitions"] >= answer["states"] - 1  # every configuration but the first was reached by a move


def test_a_time_budget_too_small_is_inconclusive() -> None:
    code, answer = verify_json(str(TASK), "--cell", str(CELL), "--timeout", "1e-9")
    assert code == 3 and answer["verdict"] == "inconclusive"
    assert answer["problem"] == "the time budget of 1e-09 s ran out before every interleaving was explored"
    # the clock is read once every 64 configurations taken from the queue: the first reading ends the search
    assert (answer["states"], answer["transitions"]) == (64, 66)


def test_an_event_the_controller_does_not_wait_for_is_refuted(tmp_path: Path) -> None:
    closed = '<state id="closed" pnp:concept="Closed">'
    chatty = closed + ('<onentry><send event="tick" delay="1s"/></onentry>'
                       '<transition event="tick"><send event="xirp.event.still_closed" type="xirp"/></transition>')
    chart = (D / "devices" / "gripper.scxml").read_text(encoding="utf-8").replace(closed, chatty)
    result = service.verify(TASK, seeded_cell(tmp_path, chart))
    assert result.verdict == "refuted"
    assert result.problem.startswith("the controller does not wait for gripper.xirp.event.still_closed")


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_a_timeout_that_is_not_a_positive_number_is_bad_input(value: str) -> None:
    result = runner.invoke(app, ["verify", str(TASK), "--cell", str(CELL), "--timeout", value])
    assert result.exit_code == 2 and "--timeout" in result.output


def test_generate_writes_nothing_for_a_refuted_program_unless_told_not_to_verify(tmp_path: Path) -> None:
    cell = seeded_cell(tmp_path / "cell", napping_gripper())
    refused = runner.invoke(app, ["generate", str(TASK), "--cell", str(cell), "-o", str(tmp_path / "out")])
    assert refused.exit_code == 1 and "refuses xirp.request.Close" in refused.stderr
    assert not (tmp_path / "out").exists()
    written = runner.invoke(app, ["generate", str(TASK), "--cell", str(cell), "-o", str(tmp_path / "out"),
                                  "--no-verify"])
    assert written.exit_code == 0 and (tmp_path / "out" / "bin-picking.task.scxml").is_file()


def test_generate_says_the_program_is_proved(tmp_path: Path) -> None:
    result = runner.invoke(app, ["generate", str(TASK), "--cell", str(CELL), "-o", str(tmp_path), "--json"])
    assert result.exit_code == 0, result.output
    answer = json.loads(result.stdout)
    assert answer["verification"]["verdict"] == "proved" and answer["verification"]["states"] > 0


def pairs() -> list[tuple[Path, Path]]:
    """Every shipped task on every shipped cell, and the test libraries' tasks on their cells."""
    shipped = [(t, c) for t in sorted((D / "tasks").glob("*.yaml")) for c in sorted((D / "cells").glob("*.yaml"))]
    libraries = [(t, c) for lib in sorted(LIBRARIES.iterdir()) for t in sorted(lib.glob("tasks/*.yaml"))
                 for c in sorted(lib.glob("cells/*.yaml"))]
    return shipped + libraries


EXPECTED = {
    # (task, cell): (plausible, verdict of verification (None: not verified), the kinds of problem the check finds)
    ("bin-picking-in-rounds", "assembly"): (False, None, {"absent", "device_limit", "wrong_state"}),
    ("bin-picking-in-rounds", "bin-picking"): (True, "proved", set()),
    ("bin-picking-invalid", "assembly"): (False, None, {"no_device", "wrong_state"}),
    ("bin-picking-invalid", "bin-picking"): (False, None, {"wrong_state"}),
    ("bin-picking-localized", "assembly"): (False, None, {"absent", "device_limit", "wrong_state"}),
    ("bin-picking-localized", "bin-picking"): (True, "proved", set()),
    ("bin-picking-then-home", "assembly"): (False, None, {"absent", "branch_join", "device_limit", "wrong_state"}),
    ("bin-picking-then-home", "bin-picking"): (True, "proved", set()),
    ("bin-picking-until-empty", "assembly"): (False, None, {"absent", "device_limit", "wrong_state"}),
    ("bin-picking-until-empty", "bin-picking"): (True, "proved", set()),
    ("bin-picking", "assembly"): (False, None, {"absent", "device_limit", "wrong_state"}),
    ("bin-picking", "bin-picking"): (True, "proved", set()),
    ("pick-and-place", "assembly"): (False, None, {"device_limit", "no_device"}),
    ("pick-and-place", "bin-picking"): (True, "proved", set()),
    ("bin-picking-in-rounds", "mixed"): (False, None, {"absent"}),  # binds binpicking-pc, not in the mixed cell
    ("bin-picking-invalid", "mixed"): (False, None, {"wrong_state"}),
    ("bin-picking-localized", "mixed"): (False, None, {"absent"}),
    ("bin-picking-then-home", "mixed"): (False, None, {"absent"}),
    ("bin-picking-until-empty", "mixed"): (False, None, {"absent"}),
    ("bin-picking", "mixed"): (False, None, {"absent"}),
    ("pick-and-place", "mixed"): (True, "proved", set()),
    ("pick-and-screw", "assembly"): (False, None, {"absent", "device_limit", "wrong_state"}),
    ("pick-and-screw", "bin-picking"): (False, None, {"absent"}),
    ("pick-and-screw", "mixed"): (True, "proved", set()),  # XIRP, UPnP and OPC UA devices
    ("opcua-glue", "opcua-glue-cell"): (True, "proved", set()),
    ("machine-tending", "machine-tending"): (True, "proved", set()),
    ("machining-door-open", "machine-tending"): (False, None, {"wrong_state"}),
    ("close-gripper", "bin-picking-locked"): (False, None, {"stuck"}),
    ("pick-where-localized", "far-part"): (True, "refuted", set()),  # its PC reports a pose beyond reach
    ("glue", "glue-cell"): (True, "proved", set()),
    ("iri-then-home", "iri-outcomes"): (True, "proved", set()),
    ("iri-until-empty", "iri-outcomes"): (True, "proved", set()),
    ("bin-picking-counting", "bin-picking-counting"): (True, "proved", set()),
    ("gentle-tending", "tending-without-gripper"): (False, None, {"absent", "no_device"}),
    ("tending-door-shut", "tending-without-gripper"): (False, None, {"wrong_state", "no_device"}),
    ("screw-twice", "packml-screwing"): (True, "proved", set()),  # a hierarchical (PackML-style) device chart
    ("approach-while-opening", "timed-cell"): (True, "proved", set()),  # declared durations, a motion model
    ("approach-while-opening", "two-robots"): (False, None, {"ambiguous"}),  # two robots fit: bind one
    ("pick-place-timed", "timed-cell"): (True, "proved", set()),
    ("pick-place-timed", "two-robots"): (False, None, {"ambiguous"}),
    ("move-near", "mm-arm"): (True, "proved", set()),  # an arm taking its poses in "mm deg"
    ("move-far", "mm-arm"): (False, None, {"device_limit"}),  # 2 m is beyond its 1450 mm reach
    ("move-near", "mm-arm-localizing"): (True, "proved", set()),
    ("move-far", "mm-arm-localizing"): (False, None, {"device_limit"}),
    ("move-to-part", "mm-arm"): (False, None, {"no_device"}),  # no localizer, no 3D sensor
    ("move-three", "mm-arm"): (True, "proved", set()),  # two steps share a chart, their poses read at run time
    ("move-three", "mm-arm-localizing"): (True, "proved", set()),
    ("move-to-part", "mm-arm-localizing"): (True, "proved", set()),  # the reported pose in m, the arm's in mm
}
"""What the check and verification answer for every pair: a change in either is a failing row, never a skip."""


def test_the_table_covers_every_shipped_and_library_task_on_its_cells() -> None:
    assert sorted((t.stem, c.stem) for t, c in pairs()) == sorted(EXPECTED)


@pytest.mark.parametrize(("task", "cell"), pairs(), ids=lambda p: p.stem)
def test_every_task_is_plausible_and_proved_on_a_cell_exactly_as_the_table_says(task: Path, cell: Path) -> None:
    plausible, verdict, kinds = EXPECTED[(task.stem, cell.stem)]
    checked = service.check(task, cell)
    assert (checked.plausible, {p.kind for p in checked.problems}) == (plausible, kinds)
    if plausible:  # verification is only for a plausible task (generate refuses the others before it)
        result = service.verify(task, cell)
        assert result.verdict == verdict, "\n".join(result.lines())
        if cell.stem == "far-part":  # the closed world knows the pose the localizer reports
            assert "reaches at most 1.45 m from its base" in (result.problem or "")
