"""Teach in the page: the step dialog's "Teach" beside a pose reads where the simulated robot was guided to."""

from __future__ import annotations

import asyncio
from concurrent.futures import ThreadPoolExecutor

import httpx
from playwright.sync_api import Page, expect

from plugnproduce.protocols import xirp
from tests.hmi.conftest import Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed

GUIDED = [0.45, -0.1, 0.3, 0.0, 180.0, 30.0]


async def guide(endpoint: str, pose: list[float]) -> None:
    """The operator's hand: move the robot to ``pose`` straight over XIRP, and wait until it is there."""
    client = await xirp.XirpClient.connect_endpoint(endpoint, timeout=WAIT)
    try:
        await client.request("MoveTo", {"TargetPose": pose, "Speed": 10}, timeout=WAIT)
        deadline = asyncio.get_running_loop().time() + WAIT
        while await client.state(timeout=WAIT) != "at_pose":
            assert asyncio.get_running_loop().time() < deadline, "the robot did not reach the pose"
            await asyncio.sleep(0.02)
    finally:
        await client.close()


def test_teach_puts_the_pose_the_robot_reports_into_the_place_pose(page: Page, served: Served) -> None:
    assert httpx.get(f"{served.url}/api/teach", timeout=WAIT).json() == {"reports": {"robot": ["TargetPose"]}}
    with ThreadPoolExecutor(1) as hand:  # a loop of its own: the browser's driver runs one in this thread
        hand.submit(asyncio.run, guide(served.hmi.source.sim.devices["robot"].endpoint, GUIDED)).result(WAIT * 2)
    page.get_by_role("button", name="Add place to the task", exact=True).click()
    dialog = page.locator("#step-dialog")
    expect(dialog).to_be_visible()
    expect(dialog.get_by_role("button", name="Teach exposure")).to_have_count(0)  # no device reports it
    dialog.get_by_role("button", name="Teach place pose").click()
    expect(dialog.locator(".taught").first).to_have_text("taught from robot (at_pose)")
    for axis, value in zip(("x", "y", "z", "rx", "ry", "rz"), GUIDED, strict=True):
        expect(dialog.locator(f"#param-place_pose-{axis}")).to_have_value(f"{value:g}")
    screenshot(page, "step-dialog-teach")
    with page.expect_response("**/api/task/validate"):
        dialog.get_by_role("button", name="Add step").click()
    expect(dialog).to_be_hidden()
    params = page.evaluate("() => JSON.parse(localStorage.getItem('pnp-task'))")
    assert params["steps"][0]["params"]["place_pose"] == GUIDED
