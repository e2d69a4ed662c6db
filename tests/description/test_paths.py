"""Path search in Device State Charts."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys

import pytest

from plugnproduce import service
from plugnproduce.description.model import Command
from plugnproduce.description.paths import NoPath, find_path

P = "http://plugnproduce.org/ontology#"


@pytest.fixture(scope="module")
def catalogue():
    return {d.id: d for d in service.catalogue()}


def test_gripper_open_to_closed_is_the_papers_figure_5(catalogue, taxonomy) -> None:
    path = find_path(catalogue["gripper"], "open", P + "Closed", taxonomy)
    assert [(t.source, t.target) for t in path.steps] == [("open", "closing"), ("closing", "closed")]
    assert path.steps[0].request == Command("xirp", "request", "Close")
    assert path.steps[1].sends == (Command("xirp", "event", "gripper_closed"),)


def test_subsumption_counts(catalogue, taxonomy) -> None:
    vacuum = catalogue["vacuum-gripper"]
    # 'holding' is annotated ClosedWithPart, which satisfies Closed; 'released' is Released ≡ Open.
    assert find_path(vacuum, "released", P + "Closed", taxonomy).target == "holding"
    assert find_path(vacuum, "holding", P + "Open", taxonomy).target == "released"
    assert find_path(vacuum, "released", P + "Open", taxonomy).steps == ()


def test_equal_paths_prefer_the_one_that_takes_the_parameters(catalogue, taxonomy) -> None:
    robot = catalogue["robot"]
    plain = find_path(robot, "at_pose", P + "Moving", taxonomy)
    with_pose = find_path(robot, "at_pose", P + "Moving", taxonomy, frozenset({P + "TargetPose"}))
    assert plain.target == "homing"  # first by state id when nothing is handed over
    assert with_pose.target == "moving" and with_pose.steps[0].request.name == "MoveTo"


def test_no_path_names_device_state_and_concept(catalogue, taxonomy) -> None:
    with pytest.raises(NoPath, match="device conveyor: no path .* from state 'stopped' to a state of concept Open"):
        find_path(catalogue["conveyor"], "stopped", P + "Open", taxonomy)


def _walk(path) -> list[tuple[str, str, str | None]]:
    return [(t.source, t.target, t.request.name if t.request else None) for t in path.steps]


def test_path_search_does_not_depend_on_the_order_of_the_chart(catalogue, taxonomy) -> None:
    """From at_pose two paths of one request reach a Moving state (MoveTo → moving, Home → homing): the tie is
    broken by what the step hands over, then by state ids, whatever order the chart lists states and transitions."""
    robot = catalogue["robot"]
    orders = [robot, dataclasses.replace(robot, states=robot.states[::-1], transitions=robot.transitions[::-1])]
    orders += [dataclasses.replace(robot, transitions=robot.transitions[k:] + robot.transitions[:k])
               for k in range(1, len(robot.transitions))]
    plain = {tuple(_walk(find_path(r, "at_pose", P + "Moving", taxonomy))) for r in orders}
    with_pose = {tuple(_walk(find_path(r, "at_pose", P + "Moving", taxonomy, frozenset({P + "TargetPose"}))))
                 for r in orders}
    assert plain == {(("at_pose", "homing", "Home"),)}
    assert with_pose == {(("at_pose", "moving", "MoveTo"),)}


def test_path_search_does_not_depend_on_the_hash_seed() -> None:
    code = ("from plugnproduce import service\nfrom plugnproduce.description.paths import find_path\n"
            "from plugnproduce.ontology.taxonomy import load_taxonomy\n"
            "robot = next(d for d in service.catalogue() if d.id == 'robot')\n"
            f"path = find_path(robot, 'at_pose', '{P}Moving', load_taxonomy())\n"
            "print([(t.source, t.target) for t in path.steps])\n")
    answers = set()
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        answers.add(done.stdout.strip())
    assert answers == {"[('at_pose', 'homing')]"}


MOVING = ("robot", "cobot", "scara", "conveyor", "cnc", "screwdriver")


def test_every_built_in_device_that_moves_declares_a_safe_stop(catalogue) -> None:
    for name in MOVING:
        stops = catalogue[name].stops
        assert stops and all(t.request is not None and t.request.name == "Halt" for t in stops), name
    robot = catalogue["robot"]
    assert {s.id for s in robot.states} == {t.source for t in robot.stops}  # the robot can be stopped in any state


def test_a_safe_stop_is_never_planned_with(catalogue, taxonomy) -> None:
    """Halt leaves 'moving' for 'at_pose' as motion.done does, but a plan only ever waits for the motion."""
    for name in MOVING:
        assert all(t.request is None or t.request.name != "Halt" for t in catalogue[name].transitions), name
    path = find_path(catalogue["robot"], "moving", P + "AtPose", taxonomy)
    assert [t.event for t in path.steps] == ["motion.done"]
    commands = service.generate(service.builtin("tasks", "bin-picking.yaml"),
                                service.builtin("cells", "bin-picking.yaml")).task.commands()
    assert "Halt" not in {c.name for _, _, c in commands}
