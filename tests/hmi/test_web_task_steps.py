"""The page in headless Chromium: a generated Task State Chart drawn step by step, one step expanded
into its regions and the others collapsed to their process and binding.

Each test waits for what it expects to see, never for a fixed time, and saves a screenshot.
"""

from __future__ import annotations

import re

from playwright.sync_api import Page, expect

from plugnproduce import service
from tests.hmi.conftest import screenshot

CHART_SHOWN = "() => { const i = document.querySelector('#chart-img'); return i.complete && i.naturalWidth > 0; }"
DRAWN = """async () => {
  const svg = await (await fetch(document.querySelector('#chart-img').src)).text();
  const doc = new DOMParser().parseFromString(svg, 'image/svg+xml');
  const titles = (kind) => [...doc.querySelectorAll(`g.${kind}`)].map((g) => g.querySelector('title').textContent);
  const text = (id) => [...doc.querySelectorAll('g.node')].filter((g) => g.querySelector('title').textContent === id)
    .flatMap((g) => [...g.querySelectorAll('text')].map((t) => t.textContent));
  return { clusters: titles('cluster'), nodes: titles('node'), step1: text('pnp_step_1'), step2: text('pnp_step_2') };
}"""
"""What the picture shown draws: its clusters and nodes (by Graphviz id), and the text of steps 1 and 2."""


def _generate_bin_picking(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Generate code").click()
    expect(page.locator("#chart-steps")).to_be_visible()
    page.wait_for_function(CHART_SHOWN)


def test_a_task_chart_starts_with_its_first_step_expanded(page: Page) -> None:
    _generate_bin_picking(page)
    expect(page.locator("#chart-step")).to_have_value("1")
    expect(page.locator("#chart-step option")).to_have_count(7)  # none, then the six steps
    expect(page.locator("#chart-img")).to_have_attribute("src", re.compile(r"/api/charts/generated/\w+/bin-picking.task.scxml.svg\?step=1"))
    expect(page.get_by_role("button", name="Expand the previous step")).to_be_disabled()


def test_expanding_a_step_collapses_the_others_to_process_and_binding(page: Page) -> None:
    _generate_bin_picking(page)
    page.locator("#chart-step").select_option("3")
    expect(page.locator("#chart-img")).to_have_attribute("src", re.compile(r".*\.svg\?step=3$"))
    page.wait_for_function(CHART_SHOWN)
    drawn = page.evaluate(DRAWN)
    assert "cluster_pnp_step_3" in drawn["clusters"]
    assert [n for n in drawn["nodes"] if n.startswith("pnp_step_")] == [f"pnp_step_{n}" for n in (1, 2, 4, 5, 6)]
    assert any(n.startswith("s3_robot") for n in drawn["nodes"])  # the expanded step's regions
    assert not any(n.startswith(("s1_", "s2_")) for n in drawn["nodes"])  # the collapsed steps' are not drawn
    assert drawn["step1"][0] == "1 · bin-pick" and any("robot: robot" in t for t in drawn["step1"])
    assert drawn["step2"][0] == "2 · place" and any("gripper: gripper" in t for t in drawn["step2"])
    screenshot(page, "charts-task-step-by-step")


def test_the_step_buttons_walk_the_steps(page: Page) -> None:
    _generate_bin_picking(page)
    page.get_by_role("button", name="Expand the next step").click()
    expect(page.locator("#chart-step")).to_have_value("2")
    expect(page.locator("#chart-img")).to_have_attribute("src", re.compile(r".*\.svg\?step=2$"))
    page.locator("#chart-step").select_option("6")
    expect(page.get_by_role("button", name="Expand the next step")).to_be_disabled()
    page.get_by_role("button", name="Expand the previous step").click()
    expect(page.locator("#chart-img")).to_have_attribute("src", re.compile(r".*\.svg\?step=5$"))
    page.locator("#chart-step").select_option("")
    expect(page.locator("#chart-img")).to_have_attribute("src", re.compile(r".*bin-picking\.task\.scxml\.svg$"))


def test_a_hundred_step_task_is_drawn_step_by_step(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.locator("#task-repeat").fill("50")
    page.locator("#task-repeat").dispatch_event("change")
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Generate code").click()
    expect(page.locator("#chart-step option")).to_have_count(101)
    page.locator("#chart-step").select_option("57")
    expect(page.locator("#chart-img")).to_have_attribute("src", re.compile(r".*\.svg\?step=57$"))
    page.wait_for_function(CHART_SHOWN)
    drawn = page.evaluate(DRAWN)
    assert drawn["clusters"].count("cluster_pnp_step_57") == 1
    assert len([n for n in drawn["nodes"] if n.startswith("pnp_step_")]) == 99
    page.wait_for_function("() => document.querySelector('#chart-frame').dataset.focused === '57'")
    screenshot(page, "charts-task-100-steps")
    focused = float(page.locator("#chart-frame").evaluate("f => f.dataset.scale"))
    page.get_by_role("button", name="Fit").click()
    assert focused > 2 * float(page.locator("#chart-frame").evaluate("f => f.dataset.scale"))  # the step, larger
