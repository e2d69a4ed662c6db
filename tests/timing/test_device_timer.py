"""One device's time: its chart's delays, its declared durations, and the simulated device's speed factor."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.model import DeviceDescription
from plugnproduce.description.quantities.durations import RequestDuration, RequestTimer
from plugnproduce.sim.device import SimulatedDevice
from plugnproduce.timing import DeviceTimer, chart_delays

ROOT = Path(__file__).parents[2]
TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
POSE = "http://plugnproduce.org/ontology#TargetPose"
SPEED = "http://plugnproduce.org/ontology#Speed"


def device(cell: Path, device_id: str) -> DeviceDescription:
    return service.cell(cell, service.knowledge((TIMED,))).device(device_id)


def test_the_chart_s_delays_are_read_per_state_and_event() -> None:
    robot = device(ROOT / "descriptions" / "cells" / "bin-picking.yaml", "robot")
    assert chart_delays(robot) == {("moving", "motion.done"): 0.25, ("homing", "motion.done"): 0.25}


def test_a_motion_takes_the_distance_from_the_previous_pose_over_the_speed() -> None:
    timer = RequestTimer((RequestDuration("MoveTo", motion_of=POSE, top_speed=0.5, speed_share=SPEED),), 80.0)
    assert timer.seconds("MoveTo", {"TargetPose": [0.4, 0.0, 0.4, 0, 180, 0], "Speed": 50}) is None  # from home
    assert timer.seconds("MoveTo", {"TargetPose": "0.4 0.3 0.0 0 180 0", "Speed": 50}) == pytest.approx(0.5 / 0.25)
    # a request for more than the speed limit moves at the limit; a request without a speed, at the limit too
    assert timer.seconds("MoveTo", {"TargetPose": [0.4, -0.3, 0.0, 0, 180, 0], "Speed": 100}) == pytest.approx(1.5)
    assert timer.seconds("MoveTo", {"TargetPose": [0.4, -0.3, 0.4, 0, 180, 0]}) == pytest.approx(1.0)
    assert timer.seconds("Home", {}) is None  # no duration declared: the chart's delay counts


def test_a_declared_time_replaces_the_next_delay_once() -> None:
    gripper = DeviceTimer(device(TIMED / "cells" / "timed-cell.yaml", "tc-gripper"))
    assert gripper.request("Close", {}) == 0.4
    assert gripper.delay(0.12) == 0.4
    assert gripper.delay(0.12) == 0.12  # a later delay without a request before it: as the chart says


def test_the_simulated_device_divides_its_durations_by_the_speed_factor() -> None:
    gripper = SimulatedDevice(device(TIMED / "cells" / "timed-cell.yaml", "tc-gripper"), speed=4.0)
    policy = gripper.interpreter.delay_policy
    assert policy is not None
    assert policy(0.12) == pytest.approx(0.03)
    gripper.timer.request("Open", {})
    assert policy(0.12) == pytest.approx(0.3 / 4)


@pytest.mark.parametrize("speed", [0.0, -1.0, float("nan"), float("inf")])
def test_a_speed_factor_must_be_a_positive_number(speed: float) -> None:
    with pytest.raises(ValueError, match="speed factor"):
        SimulatedDevice(device(TIMED / "cells" / "timed-cell.yaml", "tc-gripper"), speed=speed)
