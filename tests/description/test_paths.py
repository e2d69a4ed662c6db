"""Path search in Device State Charts."""

from __future__ import annotations

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


def test_path_search_is_deterministic(catalogue, taxonomy) -> None:
    paths = {find_path(catalogue["cnc"], "door_closed", P + "MachineIdle", taxonomy) for _ in range(5)}
    assert len(paths) == 1


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
