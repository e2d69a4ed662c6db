"""Resume in the page: a gripper fault stops the until-empty task; Resume shows the rest re-planned from the
devices' states, and Continue runs it until the simulated bin is empty."""

from __future__ import annotations

import httpx
import pytest
from playwright.sync_api import Page, expect

from plugnproduce import service
from plugnproduce.sim.bin import SimulatedBin
from tests.hmi.conftest import AUTH, Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed

UNTIL_EMPTY = service.builtin("tasks", "bin-picking-until-empty.yaml")


@pytest.mark.parametrize("served", [("gripper:error-response:Close", SimulatedBin(3, seed=4))], indirect=True)
def test_resume_after_a_gripper_fault_shows_the_plan_and_empties_the_bin(page: Page, served: Served) -> None:
    page.locator("#import").set_input_files(str(UNTIL_EMPTY))
    expect(page.locator("#verdict .ok")).to_be_visible()
    expect(page.get_by_role("button", name="Resume")).to_be_hidden()
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-status")).to_contain_text("failed")
    failed = served.hmi.runner.runs()[-1]
    page.get_by_role("button", name="Resume").click()
    plan = page.locator("#resume-plan")
    expect(plan).to_be_visible()
    expect(plan.locator("#resume-what")).to_contain_text(
        "Plan: the rest of task bin-picking-until-empty from step 1, 6 step(s), from the devices' states")
    expect(plan.locator("#resume-what")).to_contain_text("robot at_pose")
    expect(plan.locator("#resume-task")).to_contain_text("until: BinEmpty")
    screenshot(page, "run-resume-plan")
    assert served.hmi.source.sim.bin is not None and len(served.hmi.source.sim.bin.parts) == 3  # nothing sent yet
    plan.get_by_role("button", name="Continue").click()
    expect(plan).to_be_hidden()
    expect(page.locator("#run-status")).to_contain_text("succeeded")
    assert served.hmi.source.sim.bin.parts == []
    resumed = served.hmi.runner.runs()[-1]
    assert resumed != failed
    kinds = [r["kind"] for r in served.hmi.runner.journal(resumed)[:4]]
    assert kinds == ["start", "stopped", "replan", "continue"]
    page.locator("#journal-box summary").click()
    expect(page.locator("#journal")).to_contain_text(f"resumes run {failed}, which failed at step 2")
    expect(page.locator("#journal")).to_contain_text("continues, confirmed by the operator")
    answer = httpx.post(f"{served.url}/api/runs/{resumed}/replan", headers=AUTH, timeout=WAIT)
    assert answer.status_code == 409 and answer.json()["detail"].endswith("succeeded: nothing to resume")
