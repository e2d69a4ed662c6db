"""The page in headless Chromium: the until-empty bin-picking task built through the dialogs (a named
step, a pose taken from it, a loop until the bin is empty), then run on the simulated cell's seeded bin.

Each test waits for what it expects to see, never for a fixed time, and saves a screenshot.
"""

from __future__ import annotations

import pytest
import yaml
from playwright.sync_api import Page, expect

from plugnproduce import service
from plugnproduce.sim.bin import SimulatedBin
from tests.hmi.conftest import Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed: CI runs the suite on a loaded machine

PARTS, SEED = 3, 7
SHIPPED = service.builtin("tasks", "bin-picking-until-empty.yaml")


def _label(command: str) -> str:
    return service.knowledge().process(command).label


def _open(page: Page, command: str) -> None:
    page.get_by_role("button", name=f"Add {_label(command)} to the task", exact=True).click()
    expect(page.locator("#step-dialog")).to_be_visible()


def _add(page: Page) -> None:
    dialog = page.locator("#step-dialog")
    with page.expect_response("**/api/task/validate"):
        dialog.get_by_role("button", name="Add step").click()
    expect(dialog).to_be_hidden()


def _build_until_empty(page: Page) -> None:
    """Scan and localise (named 'localize'), pick where it found the part, place; loop until BinEmpty."""
    page.locator("#task-name").fill("bin-picking-until-empty")
    page.locator("#task-name").press("Tab")
    page.locator("#task-description").fill(yaml.safe_load(SHIPPED.read_text(encoding="utf-8"))["description"])
    page.locator("#task-description").press("Tab")
    _open(page, "localize-part")
    page.locator("#step-name").fill("localize")
    page.locator("#param-exposure").fill("25")
    _add(page)
    _open(page, "pick")
    source = page.locator("#param-pick_pose-source")
    expect(source.locator("option")).to_have_text(["entered here", "from part pose of step 1 (localize)"])
    source.select_option(label="from part pose of step 1 (localize)")
    expect(page.locator("#param-pick_pose-x")).to_be_disabled()
    page.locator("#param-grip_force").fill("45")
    _add(page)
    _open(page, "place")
    page.locator("#param-speed").fill("80")
    _add(page)
    expect(page.locator("#steps li.step").nth(1)).to_contain_text("pick pose ← part pose of localize")
    page.get_by_role("button", name="Add loop").click()
    dialog = page.locator("#loop-dialog")
    expect(dialog).to_be_visible()
    expect(page.locator("#loop-until option")).to_have_text(["no outcome: only the maximum", "PartFound", "BinEmpty",
                                                             "NoPartFound (reported as BinEmpty)"])
    page.locator("#loop-until").select_option("BinEmpty")
    page.locator("#loop-max").fill("100")
    dialog.get_by_role("button", name="Save loop").click()
    expect(dialog).to_be_hidden()
    expect(page.locator("#steps .loop-head")).to_have_text(
        "Loop over steps 1–3 until BinEmpty, at most 100 timesEdit loopRemove loop")
    expect(page.locator("#verdict .ok")).to_contain_text("Plausible")


def test_the_until_empty_task_is_built_through_the_dialogs_and_exports_as_the_shipped_file(page: Page) -> None:
    _build_until_empty(page)
    screenshot(page, "task-editor-until-empty")
    with page.expect_download() as download:
        page.get_by_role("button", name="Export YAML").click()
    built = yaml.safe_load(download.value.path().read_text(encoding="utf-8"))
    shipped = yaml.safe_load(SHIPPED.read_text(encoding="utf-8"))
    assert built == {  # the shipped task, with the values equal to the defaults and the only bindings left out
        "task": shipped["task"], "description": shipped["description"],
        "steps": [{"loop": {"until": "BinEmpty", "max": 100, "steps": [
            {"name": "localize", "command": "localize-part", "params": {"exposure": 25}},
            {"command": "pick", "params": {"grip_force": 45, "pick_pose": {"from": "localize", "output": "part_pose"}}},
            {"command": "place", "params": {"speed": 80}}]}}]}
    assert shipped["steps"][0]["loop"]["steps"][1]["params"]["pick_pose"] == {"from": "localize", "output": "part_pose"}


def test_a_loop_needs_a_way_out_and_does_not_overlap_another(page: Page) -> None:
    _build_until_empty(page)
    page.get_by_role("button", name="Add loop").click()
    page.locator("#loop-first").select_option("2")
    page.get_by_role("button", name="Save loop").click()
    expect(page.locator("#loop-error")).to_have_text("Steps 1–3 are in a loop already; loops do not nest or overlap.")
    page.get_by_role("button", name="Cancel").click()
    page.get_by_role("button", name="Edit Loop over steps 1–3 until BinEmpty, at most 100 times").click()
    page.locator("#loop-until").select_option("")
    page.locator("#loop-max").fill("")
    page.get_by_role("button", name="Save loop").click()
    expect(page.locator("#loop-error")).to_have_text("A loop needs a way out: an outcome to end on, a maximum, or both.")


@pytest.mark.parametrize("served", [SimulatedBin(PARTS, SEED)], indirect=True)
def test_the_until_empty_run_shows_its_iterations_and_each_pose_from_localize_to_pick(page: Page, served: Served) -> None:
    expected = sorted((p.pose for p in SimulatedBin(PARTS, SEED).parts), key=lambda pose: -pose[2])  # top first
    _build_until_empty(page)
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-status")).to_contain_text("succeeded", timeout=120_000)
    expect(page.locator("#run-loops")).to_have_text(f"Loop over steps 1–3 until BinEmpty, at most 100 times: "
                                                    f"iteration {PARTS + 1}")
    produced = page.locator("#run-values li.produced[data-value='localize.part_pose']")
    used = page.locator("#run-values li.used[data-value='localize.part_pose']")
    expect(used).to_have_count(PARTS)  # one pick per part; the last iteration ends at localize
    for i in range(PARTS):
        pose = "(" + ", ".join(f"{v:g}" for v in expected[i]) + ")"
        expect(produced.nth(i)).to_contain_text(f"iteration {i + 1} localize.part_pose = {pose}, produced by "
                                                "step 1 (localize) on binpicking-pc")
        expect(used.nth(i)).to_contain_text(f"iteration {i + 1} localize.part_pose = {pose}, used by step 2 (pick) "
                                            "as pick_pose on robot")
    expect(page.locator("#run-values li.produced[data-value='outcome']").last).to_contain_text(
        f"iteration {PARTS + 1} outcome = BinEmpty")
    screenshot(page, "run-until-empty")
    assert served.hmi.source.sim.bin is not None and served.hmi.source.sim.bin.parts == []
