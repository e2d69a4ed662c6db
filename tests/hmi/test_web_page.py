"""The web page in real headless Chromium over the simulated cell: dialogs, refusals, check and repair,
plug/unplug (seen through discovery), runs by the executor.

Every test waits for what it expects to see (selectors, responses), never for a fixed time,
and saves a screenshot of its main view under ``artifacts/screenshots/``.
"""

from __future__ import annotations

import pytest
import yaml
from playwright.sync_api import APIResponse, Page, Route, expect
from playwright.sync_api import TimeoutError as PlaywrightTimeout

from plugnproduce import service
from tests.hmi.conftest import AUTH, Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed: CI runs the suite on a loaded machine

CHART_SHOWN = "() => { const i = document.querySelector('#chart-img'); return i.complete && i.naturalWidth > 0; }"
"""The chart picture has loaded (a function, not an expression: the page's policy forbids eval)."""


def add_step(page: Page, command: str, values: dict[str, str | list[str]] | None = None) -> None:
    """Add a process command through its dialog, filling the given fields."""
    page.get_by_role("button", name=f"Add {_label(command)} to the task", exact=True).click()
    dialog = page.locator("#step-dialog")
    expect(dialog).to_be_visible()
    for name, value in (values or {}).items():
        if isinstance(value, list):
            for axis, v in zip(("x", "y", "z", "rx", "ry", "rz"), value, strict=True):
                dialog.locator(f"#param-{name}-{axis}").fill(v)
        else:
            dialog.locator(f"#param-{name}").fill(value)
    with page.expect_response("**/api/task/validate"):
        dialog.get_by_role("button", name="Add step").click()
    expect(dialog).to_be_hidden()


def _label(command: str) -> str:
    return service.knowledge().process(command).label


def steps(page: Page) -> list[str]:
    return page.locator("#steps li.step").evaluate_all("els => els.map(e => e.dataset.command)")


STEPS_ARE = ("want => JSON.stringify([...document.querySelectorAll('#steps li.step')].map(e => e.dataset.command))"
             " === JSON.stringify(want)")


def expect_steps(page: Page, commands: list[str]) -> None:
    """The task editor comes to list these steps, in this order (the page redraws after a key or click)."""
    try:
        page.wait_for_function(STEPS_ARE, arg=commands, timeout=WAIT * 1000)
    except PlaywrightTimeout:
        assert steps(page) == commands


def test_build_the_bin_picking_task_through_the_dialogs(page: Page) -> None:
    page.locator("#task-name").fill("bin-picking")
    page.locator("#task-name").press("Tab")
    add_step(page, "bin-pick", {"grip_force": "45", "exposure": "25"})
    add_step(page, "place", {"place_pose": ["0.55", "-0.25", "0.08", "0", "180", "0"], "speed": "80"})
    page.locator("#task-repeat").fill("3")
    page.locator("#task-repeat").press("Tab")
    expect_steps(page, ["bin-pick", "place"])
    expect(page.locator("#steps li.step").first).to_contain_text("grip force 45 N")
    page.get_by_role("button", name="Check", exact=True).click()
    expect(page.locator("#verdict .ok")).to_contain_text("Plausible")
    screenshot(page, "task-editor-bin-picking")
    with page.expect_download() as download:
        page.get_by_role("button", name="Export YAML").click()
    task = yaml.safe_load(download.value.path().read_text(encoding="utf-8"))
    assert task == {"task": "bin-picking", "repeat": 3, "steps": [  # values equal to the defaults are left out
        {"command": "bin-pick", "params": {"grip_force": 45, "exposure": 25}},
        {"command": "place", "params": {"place_pose": [0.55, -0.25, 0.08, 0, 180, 0], "speed": 80}}]}


def test_an_out_of_range_value_is_refused_with_the_shape_message(page: Page) -> None:
    page.get_by_role("button", name="Add pick to the task", exact=True).click()
    field = page.locator("#param-grip_force")
    expect(field).to_have_attribute("min", "10")
    expect(field).to_have_attribute("max", "140")
    field.fill("500")
    with page.expect_response("**/api/task/validate"):
        page.get_by_role("button", name="Add step").click()
    error = page.locator("[data-param='grip_force'] .field-error")
    expect(error).to_have_text("step 1: parameter 'grip_force' is 500 N; expected a value from 10 to 140 N")
    expect(field).to_have_attribute("aria-invalid", "true")
    expect(field).to_be_focused()
    expect(page.locator("#step-dialog")).to_be_visible()
    screenshot(page, "dialog-out-of-range")
    page.keyboard.press("Escape")
    expect(page.locator("#step-dialog")).to_be_hidden()
    expect_steps(page, [])


def test_an_invalid_task_shows_its_problem_at_its_step_and_a_repair_fixes_it(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking-invalid.yaml")))
    second = page.locator("#steps li.step[data-row='1']")
    expect(second.locator(".problem")).to_contain_text("device 'gripper' (role 'gripper') is in state 'closed'")
    expect(page.locator("#steps li.step[data-row='0'] .problem")).to_have_count(0)
    first_repair = page.locator("#repair-list li.repair").first
    expect(first_repair).to_contain_text("insert place before step 2 (bin-pick)")
    second.get_by_role("button", name="Why?").click()
    second.locator(".why details.derivation > summary").click()
    second.locator(".why summary", has_text="is not in a state role 'gripper' may start from").click()
    second.locator(".why summary", has_text="device 'gripper' is in state 'closed'").click()
    expect(second.locator(".why")).to_contain_text("step 1 (bin-pick) left device 'gripper' in state 'closed'")
    screenshot(page, "check-problem-and-repairs")
    first_repair.get_by_role("button", name="Apply").click()
    expect(page.locator("#verdict .ok")).to_contain_text("Plausible")
    expect_steps(page, ["bin-pick", "place", "bin-pick", "place"])


def test_unplugging_the_gripper_takes_pick_away(page: Page, served: Served) -> None:
    pick = page.locator("#offered li[data-command='pick']")
    expect(pick).to_be_visible()
    page.get_by_role("button", name="Unplug gripper").click()
    expect(pick).to_have_count(0)
    expect(page.locator("#devices tr[data-device='gripper']")).to_have_count(0)
    expect(page.locator("#not-offered li[data-command='pick']")).to_be_visible()
    expect(page.locator("#announce")).to_contain_text("gripper unplugged")
    screenshot(page, "cell-gripper-unplugged")
    page.get_by_role("button", name="Why is pick not offered?").click()
    why = page.locator("#why-pick")
    why.locator("details.derivation > summary").click()
    expect(why).to_contain_text("no device in cell 'bin-picking' has the skill 'can grip'")
    expect(why.get_by_role("button", name="add device 'gripper' (Parallel gripper) to the cell")).to_be_visible()


def test_a_device_plugged_in_elsewhere_shows_up_live(page: Page, served: Served) -> None:
    import httpx

    httpx.post(f"{served.url}/api/cell/devices", json={"device": "conveyor"}, headers=AUTH).raise_for_status()
    expect(page.locator("#devices tr[data-device='conveyor']")).to_be_visible()
    expect(page.locator("#offered li[data-command='transport']")).to_be_visible()


def test_a_second_gripper_gives_pick_two_bindings_and_its_dialog_both_grippers(page: Page, served: Served) -> None:
    import httpx

    httpx.post(f"{served.url}/api/cell/devices", json={"device": "magnetic-gripper"}, headers=AUTH).raise_for_status()
    expect(page.locator("#offered li[data-command='pick'] .cmd-binding")).to_have_text("2 ways to bind its roles")
    page.get_by_role("button", name=f"Add {_label('pick')} to the task", exact=True).click()
    expect(page.locator("#step-dialog #role-gripper option")).to_have_text(["gripper", "magnetic-gripper"])


def test_steps_are_reordered_and_removed_from_the_keyboard(page: Page) -> None:
    add_step(page, "scan-bin")
    add_step(page, "move-to")
    add_step(page, "localize-part")
    page.get_by_role("button", name="Move step 3 (localize part) up").focus()
    page.keyboard.press("Enter")
    expect_steps(page, ["scan-bin", "localize-part", "move-to"])
    expect(page.locator("#verdict p")).to_be_visible()  # the check of the new order has answered and redrawn
    expect(page.get_by_role("button", name="Move step 2 (localize part) up")).to_be_focused()
    page.keyboard.press("Alt+ArrowUp")
    expect_steps(page, ["localize-part", "scan-bin", "move-to"])
    expect(page.locator("#verdict p")).to_be_visible()
    # its up button is disabled at the top: the keyboard stays on the step, on its first button
    expect(page.get_by_role("button", name="Edit step 1 (localize part)")).to_be_focused()
    page.get_by_role("button", name="Remove step 3 (move to)").click()
    expect_steps(page, ["localize-part", "scan-bin"])
    screenshot(page, "task-editor-reordered")


SLOW_GRIPPER = "gripper:delay-event:gripper_closed:1"
"""The simulated gripper reports closed a second late (within its 2 s timeout): time to watch the run."""


def test_a_check_still_running_when_an_import_fails_does_not_hide_the_import_s_error(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    expect(page.locator("#verdict")).to_have_attribute("aria-busy", "false")
    steps = page.locator("#steps li.step").count()
    held: list[Route] = []
    page.route("**/api/task/repair", lambda route: held.append(route))  # the next check stays in flight until released
    page.locator("#check").click()
    expect(page.locator("#verdict")).to_have_attribute("aria-busy", "true")
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking-in-rounds.yaml")))
    refused = ("This task has a loop inside a loop: the editor builds loops of the task's steps only; edit that task "
               "file by hand.")
    expect(page.locator("#verdict .error")).to_have_text(refused)
    assert len(held) == 1
    held[0].continue_()  # the check's answer (plausible) comes after the import's refusal
    expect(page.locator("#verdict")).to_have_attribute("aria-busy", "false")  # and has been read
    expect(page.locator("#verdict .error")).to_have_text(refused)
    expect(page.locator("#verdict .ok")).to_have_count(0)
    expect(page.locator("#steps li.step")).to_have_count(steps)  # the task as it was


@pytest.mark.parametrize("served", [SLOW_GRIPPER], indirect=True)
def test_a_run_the_event_stream_tells_before_its_start_is_answered_still_says_its_devices_are_simulated(
        page: Page) -> None:
    """The page learns of a run from the event stream and from the answer to its start, in either order."""
    page.locator("#import").set_input_files(str(service.builtin("tasks", "pick-and-place.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    held: list[tuple[Route, APIResponse]] = []
    page.route("**/api/runs", lambda route: held.append((route, route.fetch())))  # started; its answer held back
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-states tr[data-device='gripper'] .badge")).to_have_text("closing")  # from the stream
    assert len(held) == 1
    held[0][0].fulfill(response=held[0][1])
    expect(page.locator("#run-status")).to_contain_text("on simulated devices at speed 1")


@pytest.mark.parametrize("served", [SLOW_GRIPPER], indirect=True)
def test_a_run_on_the_simulated_cell_shows_its_step_and_device_states_to_the_end(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "pick-and-place.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-states tr[data-device='gripper'] .badge")).to_have_text("closing")
    expect(page.locator("#run-status")).to_contain_text("is running on simulated devices at speed 1 (step")
    expect(page.get_by_role("button", name="Stop")).to_be_enabled()
    expect(page.locator("#run-step")).to_contain_text("Current step: 1 of 2, pick-and-place")
    running = page.locator("#steps li.step.running")
    expect(running).to_have_attribute("data-row", "0")
    expect(running).to_have_attribute("aria-current", "step")
    expect(page.locator("#run-states tr[data-device='gripper']")).to_have_class("busy")
    screenshot(page, "run-in-progress")
    expect(page.locator("#run-status")).to_contain_text("succeeded", timeout=WAIT * 1000)
    expect(page.locator("#run-states tr[data-device='robot'] .badge")).to_have_text("at_pose")
    expect(page.locator("#devices td.state[data-device='robot'] .badge")).to_have_text("at_pose")
    page.locator("#journal-box summary").click()
    expect(page.locator("#journal")).to_contain_text("gripper is closed")
    expect(page.locator("#journal")).to_contain_text("on cell bin-picking (simulated devices, speed 1)")
    expect(page.locator("#journal")).to_contain_text("step 2: move-to")
    expect(page.locator("#fault")).to_be_hidden()
    expect(page.locator("#steps li.step.running")).to_have_count(0)


@pytest.mark.parametrize("served", [SLOW_GRIPPER], indirect=True)
def test_a_device_unplugged_during_a_run_shows_the_fault_report(page: Page, served: Served) -> None:
    import httpx

    page.locator("#import").set_input_files(str(service.builtin("tasks", "pick-and-place.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-states tr[data-device='gripper'] .badge")).to_have_text("closing")
    httpx.delete(f"{served.url}/api/cell/devices/gripper", headers=AUTH, timeout=WAIT).raise_for_status()
    fault = page.locator("#fault")
    expect(fault).to_be_visible()
    expect(fault.locator(".fault-message")).to_contain_text("lost: ")
    expect(fault).to_contain_text("gripper")
    expect(page.locator("#run-status")).to_contain_text("failed")
    screenshot(page, "run-fault-report")


def test_charts_of_devices_and_processes_are_shown(page: Page) -> None:
    page.get_by_role("button", name="Show the state chart of gripper").click()
    image = page.locator("#chart-img")
    expect(image).to_have_attribute("alt", "Device State Chart of gripper")
    page.wait_for_function(CHART_SHOWN)
    page.locator("#chart-pick").select_option(label="pick (pick)")
    expect(image).to_have_attribute("src", "/api/charts/process/pick.svg")
    page.wait_for_function(CHART_SHOWN)
    screenshot(page, "charts-process")


def test_generated_task_chart_is_shown(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "pick-and-place.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Generate code").click()
    expect(page.locator("#chart-caption")).to_have_text("Task State Chart pick-and-place.task.scxml")
    expect(page.locator("#chart-links")).to_contain_text("pick-and-place.closed-world.scxml")
    page.wait_for_function(CHART_SHOWN)
    screenshot(page, "charts-generated-task")
