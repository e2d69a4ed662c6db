"""Explain-why in the page (real headless Chromium over the simulated cell): "Why not?" shows the derivation as
one sentence with expandable detail, the engineer's view links each source line to the description, and a
counterfactual applies with one click; a repair shows its side effect before it is applied."""

from __future__ import annotations

from playwright.sync_api import Page, expect

from plugnproduce import service
from tests.hmi.conftest import screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed: CI runs the suite on a loaded machine


def test_why_not_shows_the_derivation_and_a_counterfactual_plugs_the_missing_device_in(page: Page) -> None:
    page.get_by_role("button", name="Why is transport not offered?").click()
    why = page.locator("#why-transport")
    summary = why.locator("details.derivation > summary")
    expect(summary).to_have_text("transport is not offered in cell 'bin-picking': some role cannot be filled",
                                 use_inner_text=True)
    reason = why.get_by_text("no device in cell 'bin-picking' has the skill 'can transport'")
    expect(reason).to_be_hidden()
    summary.click()
    expect(reason).to_be_visible()
    expect(why).not_to_contain_text("pnp:")
    screenshot(page, "why-not-transport")
    button = why.get_by_role("button", name="add device 'conveyor' (Belt conveyor) to the cell")
    button.click()
    expect(page.locator("#offered li[data-command='transport']")).to_be_visible()
    expect(page.locator("#devices tr[data-device='conveyor']")).to_be_visible()


def test_the_engineer_view_opens_the_description_at_the_line(page: Page) -> None:
    page.get_by_label("Engineer view").check()
    page.get_by_role("button", name="Why is screw not offered?").click()
    why = page.locator("#why-screw")
    why.locator("details.derivation > summary").click()
    why.locator("details > summary", has_text="no device in cell").click()
    expect(why.locator("code.detail", has_text="no_skill(")).to_be_visible()
    requirement = why.locator("li.node:not(:has(details))", has_text="role 'screwdriver' of screw requires")
    requirement.get_by_role("link", name="screw.ttl").click()
    dialog = page.locator("#source-dialog")
    expect(dialog).to_be_visible()
    expect(dialog.locator("mark")).to_contain_text("pnp:requiresSkill pnp:CanScrew")
    screenshot(page, "why-not-source-line")


def test_a_repair_that_drops_the_part_shows_it_before_apply_and_ranks_last(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking-invalid.yaml")))
    repairs = page.locator("#repair-list li.repair")
    expect(repairs).to_have_count(3)
    last = repairs.last
    expect(last).to_contain_text("insert open-gripper before step 2 (bin-pick)")
    expect(last.locator(".side-effect[data-kind='drops_part']")).to_contain_text("holds the part step 1 (bin-pick) picked")
    expect(repairs.first.locator(".side-effect[data-kind='drops_part']")).to_have_count(0)
    screenshot(page, "repair-side-effects")
