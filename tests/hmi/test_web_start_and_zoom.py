"""The page in headless Chromium: "Start run" only for a plausible task, with no stale step shown;
the chart view pans and zooms by wheel, drag, buttons and keys.

Each test waits for what it expects to see, never for a fixed time, and saves a screenshot.
"""

from __future__ import annotations

import pytest
from playwright.sync_api import Locator, Page, expect

from plugnproduce import service
from tests.hmi.conftest import screenshot
from tests.lines import WAIT

CHART_SHOWN = "() => { const i = document.querySelector('#chart-img'); return i.complete && i.naturalWidth > 0; }"
FITTED = "() => document.querySelector('#chart-frame').dataset.scale !== undefined"


def test_an_implausible_task_cannot_be_started_and_the_last_run_s_step_is_cleared(page: Page) -> None:
    start = page.get_by_role("button", name="Start run")
    expect(start).to_be_disabled()  # no steps yet
    expect(page.locator("#run-start-why")).to_have_text("Add steps to the task to run it.")
    page.locator("#import").set_input_files(str(service.builtin("tasks", "pick-and-place.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    expect(start).to_be_enabled()
    expect(page.locator("#run-start-why")).to_have_text("")
    start.click()
    expect(page.locator("#run-status")).to_contain_text("succeeded", timeout=WAIT * 1000)
    expect(page.locator("#run-step")).to_have_text("")  # a finished run has no current step
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking-invalid.yaml")))
    expect(page.locator("#verdict .bad")).to_be_visible()
    expect(start).to_be_disabled()
    expect(page.locator("#run-start-why")).to_have_text("The task is not plausible: repair it to run it.")
    expect(page.locator("#run-step")).to_have_text("")
    screenshot(page, "run-implausible-task")
    page.locator("#repair-list li.repair").first.get_by_role("button", name="Apply").click()
    expect(start).to_be_enabled()


def view(frame: Locator) -> tuple[float, int, int]:
    """The chart view's scale and offset, as the page reports them on the frame."""
    data = frame.evaluate("f => [f.dataset.scale, f.dataset.x, f.dataset.y]")
    return float(data[0]), int(data[1]), int(data[2])


@pytest.fixture()
def chart(page: Page) -> Locator:
    """The gripper's Device State Chart shown and fitted; its frame."""
    page.get_by_role("button", name="Show the state chart of gripper").click()
    page.wait_for_function(CHART_SHOWN)
    page.wait_for_function(FITTED)
    frame = page.locator("#chart-frame")
    frame.scroll_into_view_if_needed()  # the mouse acts on what is on screen
    return frame


def test_the_chart_zooms_with_the_buttons_and_fits_again(page: Page, chart: Locator) -> None:
    fitted, _, _ = view(chart)
    page.get_by_role("button", name="Zoom in").click()
    assert view(chart)[0] == pytest.approx(fitted * 1.25, rel=1e-3)
    page.get_by_role("button", name="Zoom out").click()
    page.get_by_role("button", name="Zoom out").click()
    assert view(chart)[0] == pytest.approx(fitted / 1.25, rel=1e-3)
    page.get_by_role("button", name="Fit").click()
    assert view(chart)[0] == pytest.approx(fitted, rel=1e-3)


def test_the_wheel_zooms_around_the_pointer(page: Page, chart: Locator) -> None:
    box = chart.bounding_box()
    assert box is not None
    px, py = box["x"] + box["width"] * 0.3, box["y"] + box["height"] * 0.4
    scale, x, y = view(chart)
    under = ((px - box["x"] - x) / scale, (py - box["y"] - y) / scale)  # the picture's point under the pointer
    page.mouse.move(px, py)
    page.mouse.wheel(0, -300)
    page.wait_for_function(f"() => Number(document.querySelector('#chart-frame').dataset.scale) > {scale}")
    scale2, x2, y2 = view(chart)
    assert scale2 > scale
    assert ((px - box["x"] - x2) / scale2, (py - box["y"] - y2) / scale2) == pytest.approx(under, abs=2)
    screenshot(page, "charts-zoomed")


def test_dragging_pans_the_chart_and_keys_do_too(page: Page, chart: Locator) -> None:
    box = chart.bounding_box()
    assert box is not None
    scale, x, y = view(chart)
    page.mouse.move(box["x"] + 100, box["y"] + 100)
    page.mouse.down()
    page.mouse.move(box["x"] + 160, box["y"] + 130, steps=4)
    page.mouse.up()
    assert view(chart) == (scale, x + 60, y + 30)
    chart.focus()
    page.keyboard.press("ArrowRight")
    assert view(chart)[1:] == (x, y + 30)
    page.keyboard.press("+")
    assert view(chart)[0] == pytest.approx(scale * 1.25, rel=1e-3)
    page.keyboard.press("0")
    assert view(chart)[0] == pytest.approx(scale, rel=1e-3)
