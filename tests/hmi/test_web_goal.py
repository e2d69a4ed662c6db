"""The Goal view in headless Chromium: a goal planned in the simulated cell, its steps shown, the task sent to
the editor, where the check finds it plausible; and an unreachable goal says what is missing."""

from __future__ import annotations

import httpx
import yaml
from playwright.sync_api import Page, expect

from plugnproduce import service
from tests.hmi.conftest import Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed

GOAL = service.builtin("goals", "empty-the-bin.yaml")


def test_a_goal_is_planned_shown_step_by_step_and_sent_to_the_editor(page: Page) -> None:
    page.locator("#goal-text").fill(GOAL.read_text(encoding="utf-8"))
    page.get_by_role("button", name="Plan", exact=True).click()
    status = page.locator("#goal-status")
    expect(status).to_have_attribute("data-status", "planned")
    expect(status).to_contain_text("Goal empty-the-bin: planned, 3 step(s), repeated until BinEmpty; "
                                   "the check finds it plausible")
    steps = page.locator("#goal-steps li")
    expect(steps).to_have_count(3)
    assert steps.evaluate_all("els => els.map(e => e.dataset.command)") == ["localize-part", "pick", "place"]
    expect(steps.nth(1)).to_contain_text("pick_pose from")  # the pick takes the pose the localisation reports
    expect(page.locator("#goal-task")).to_contain_text("until: BinEmpty")
    screenshot(page, "goal-view")
    page.get_by_role("button", name="Send to the task editor").click()
    expect(page.locator("#steps li.step")).to_have_count(3)
    assert page.locator("#steps li.step").evaluate_all("els => els.map(e => e.dataset.command)") == [
        "localize-part", "pick", "place"]
    expect(page.locator("#verdict .ok")).to_be_visible()  # the editor's own check of the planned task
    saved = page.evaluate("() => JSON.parse(localStorage.getItem('pnp-task'))")
    assert saved["loops"] and saved["loops"][0]["until"].endswith("BinEmpty")


def test_a_goal_the_cell_cannot_reach_says_what_is_missing(page: Page) -> None:
    goal = {"goal": "screw-it", "achieve": [{"command": "screw"}]}
    page.locator("#goal-text").fill(yaml.safe_dump(goal))
    page.get_by_role("button", name="Plan", exact=True).click()
    status = page.locator("#goal-status")
    expect(status).to_have_attribute("data-status", "unreachable")
    expect(status).to_contain_text("No plan reaches goal screw-it")
    expect(page.get_by_role("button", name="Send to the task editor")).to_be_hidden()


def test_a_goal_that_cannot_be_read_is_one_line_at_its_line(served: Served) -> None:
    answer = httpx.post(f"{served.url}/api/goal/plan?filename=mine.yaml", content=b"goal: x\nachieve: 3\n",
                        headers={"content-type": "application/yaml"}, timeout=WAIT)
    assert answer.status_code == 400 and answer.json()["detail"].startswith("mine.yaml:2: ")
