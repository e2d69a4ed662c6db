"""The Goal view in headless Chromium: a goal planned in the simulated cell, its steps and estimated cycle time
shown, the task sent to the editor, where the check finds it plausible; a goal written with the form; and an
unreachable goal says what is missing."""

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


def _estimate(goal: dict[str, object]) -> float:
    """The cycle time ``pnp plan`` estimates for ``goal`` on the built-in cell, as the simulated one starts."""
    k = service.knowledge()
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"), k)
    found = service.plan(service.goal_from_text(yaml.safe_dump(goal), "goal.yaml"), cell, k)
    assert not isinstance(found, service.Unreachable)
    estimate = service.cycle_time(found.task, cell, k)
    assert estimate is not None
    return float(estimate.total)


def test_the_form_writes_the_goal_as_the_goal_file_says_it_and_the_plan_shows_its_cycle_time(page: Page) -> None:
    wanted = yaml.safe_load(GOAL.read_text(encoding="utf-8"))
    del wanted["description"]
    assert yaml.safe_load(page.locator("#goal-text").input_value()) == wanted  # the form starts with the example
    form = page.locator("#goal-form")
    form.locator("#goal-achieve li button.remove").click()  # then the same goal again, field by field
    form.locator("#goal-end li button.remove").click()
    form.locator("#goal-until").select_option("")
    assert yaml.safe_load(page.locator("#goal-text").input_value()) == {"goal": "empty-the-bin", "achieve": []}
    form.locator("#goal-name").fill("empty-it")
    form.get_by_role("button", name="Add a command").click()
    form.get_by_label("command 1", exact=True).select_option("place")
    form.get_by_label("command 1: place pose").fill("0.6 -0.2 0.1 0 180 0")
    form.locator("#goal-until").select_option("BinEmpty")
    form.get_by_role("button", name="Add an end state").click()
    form.get_by_label("end state 1: device").select_option("gripper")
    form.get_by_label("end state 1: state").select_option("Open")
    assert yaml.safe_load(page.locator("#goal-text").input_value()) == {**wanted, "goal": "empty-it"}
    page.get_by_role("button", name="Plan", exact=True).click()
    expect(page.locator("#goal-status")).to_have_attribute("data-status", "planned")
    total = _estimate({**wanted, "goal": "empty-it"})
    expect(page.locator("#goal-cycle-time")).to_have_text(
        f"Estimated cycle time: {total:.2f} s per iteration of the loop (a loop that ends on an outcome is counted "
        "once; see its seconds per iteration).")
    seconds = page.locator("#goal-steps li").evaluate_all("els => els.map(e => Number(e.dataset.seconds))")
    assert len(seconds) == 3 and abs(sum(seconds) - total) < 0.01  # one round of the loop, step by step
    expect(page.locator("#goal-steps li").nth(0)).to_contain_text(f": {seconds[0]:.2f} s")
    screenshot(page, "goal-form")

