"""The page in headless Chromium: branches on a step's outcome built through the dialogs (the outcome from
those the step's process may end with, the branch's steps through the step dialog), inside a loop, to
the shipped bin-picking-then-home task; the check's findings at the branch's rows; a run on the simulated
cell's seeded bin that takes one branch while parts are found and the other when the bin is empty.

Each test waits for what it expects to see, never for a fixed time, and saves a screenshot.
"""

from __future__ import annotations

import re

import pytest
import yaml
from playwright.sync_api import Page, expect

from plugnproduce import service
from plugnproduce.sim.bin import SimulatedBin
from tests.hmi.conftest import Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed: CI runs the suite on a loaded machine

PARTS, SEED = 3, 11
LOCALIZE = "localize-part"
SHIPPED = service.builtin("tasks", "bin-picking-then-home.yaml")
OUTCOMES = ["PartFound", "BinEmpty", "NoPartFound (reported as BinEmpty)"]


class _TaskLoader(yaml.SafeLoader):
    """YAML as task files mean it: ``on`` is a key, not YAML 1.1's true."""


_TaskLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_TaskLoader.add_implicit_resolver("tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
                                  list("tTfF"))


def _task_file(text: str) -> dict[str, object]:
    task: dict[str, object] = yaml.load(text, Loader=_TaskLoader)  # noqa: S506 - a safe loader
    return task


def _label(command: str) -> str:
    return service.knowledge().process(command).label


def _save_step(page: Page) -> None:
    dialog = page.locator("#step-dialog")
    with page.expect_response("**/api/task/validate"):
        dialog.locator("#dialog-ok").click()
    expect(dialog).to_be_hidden()


def _branch_step(page: Page, command: str, title: str) -> None:
    """In the open branch dialog: add a step of ``command`` through the step dialog, titled ``title``."""
    page.locator("#branch-command").select_option(command)
    page.locator("#branch-dialog").get_by_role("button", name="Add to branch").click()
    expect(page.locator("#step-dialog")).to_be_visible()
    expect(page.locator("#dialog-title")).to_have_text(f"Add {title}: {_label(command)}")


def _localize(page: Page) -> None:
    """Step 1: localise a part, named 'localize'."""
    page.get_by_role("button", name=f"Add {_label(LOCALIZE)} to the task", exact=True).click()
    page.locator("#step-name").fill("localize")
    page.locator("#param-exposure").fill("25")
    _save_step(page)


def _open_branch(page: Page, outcome: str) -> None:
    page.get_by_role("button", name=f"Add a branch to step 1 ({_label(LOCALIZE)})").click()
    expect(page.locator("#branch-dialog")).to_be_visible()
    expect(page.locator("#branch-outcome option")).to_have_text(OUTCOMES)
    page.locator("#branch-outcome").select_option(outcome)


def _pick_in_branch(page: Page, number: str) -> None:
    _branch_step(page, "pick", f"step {number} in the PartFound branch of step 1")
    source = page.locator("#param-pick_pose-source")
    expect(source.locator("option")).to_have_text(["entered here", "from part pose of step 1 (localize)"])
    source.select_option(label="from part pose of step 1 (localize)")
    page.locator("#param-grip_force").fill("45")
    _save_step(page)


def _loop_until_empty(page: Page) -> None:
    page.get_by_role("button", name="Add loop").click()
    page.locator("#loop-until").select_option("BinEmpty")
    page.locator("#loop-max").fill("100")
    page.locator("#loop-dialog").get_by_role("button", name="Save loop").click()
    expect(page.locator("#loop-dialog")).to_be_hidden()


def _build(page: Page) -> None:
    """As the shipped task: while a part is found, localise, pick it where it was found and place it; when none
    is found, move the robot home."""
    shipped = _task_file(SHIPPED.read_text(encoding="utf-8"))
    page.locator("#task-name").fill(shipped["task"])
    page.locator("#task-name").press("Tab")
    page.locator("#task-description").fill(shipped["description"])
    page.locator("#task-description").press("Tab")
    _localize(page)
    _open_branch(page, "PartFound")
    _pick_in_branch(page, "1.1")
    _branch_step(page, "place", "step 1.2 in the PartFound branch of step 1")
    page.locator("#param-speed").fill("80")
    _save_step(page)
    expect(page.locator("#branch-steps li")).to_have_count(2)
    page.locator("#branch-dialog").get_by_role("button", name="Save branch").click()
    expect(page.locator("#branch-dialog")).to_be_hidden()
    page.get_by_role("button", name=f"Add a branch to step 1 ({_label(LOCALIZE)})").click()
    expect(page.locator("#branch-outcome option")).to_have_text(OUTCOMES[1:])  # PartFound has its branch
    page.locator("#branch-outcome").select_option("NoPartFound")
    _branch_step(page, "move-to", "step 1.3 in the NoPartFound branch of step 1")
    _save_step(page)
    page.locator("#branch-dialog").get_by_role("button", name="Save branch").click()
    page.get_by_role("button", name="Add loop").click()
    page.locator("#loop-while").select_option("PartFound")
    page.locator("#loop-max").fill("100")
    page.locator("#loop-dialog").get_by_role("button", name="Save loop").click()
    expect(page.locator("#loop-dialog")).to_be_hidden()


def _as_built(items: list[dict[str, object]]) -> list[dict[str, object]]:
    """A task file's items as the editor writes them: no value equal to its default, no binding (each role of
    the shipped tasks has one device that fits)."""
    out: list[dict[str, object]] = []
    for item in items:
        if "loop" in item:
            loop = dict(item["loop"])  # type: ignore[call-overload]
            out.append({"loop": {**loop, "steps": _as_built(loop["steps"])}})
            continue
        step = {k: v for k, v in item.items() if k != "bind"}
        defaults = {p.name: p.default for p in service.knowledge().process(str(step["command"])).parameters}
        params = {n: v for n, v in dict(step.get("params") or {}).items()  # type: ignore[call-overload]
                  if not _same(v, defaults.get(n))}
        step = {k: v for k, v in step.items() if k != "params"} | ({"params": params} if params else {})
        if "on" in step:
            step["on"] = {o: _as_built(body) for o, body in step["on"].items()}  # type: ignore[attr-defined]
        out.append(step)
    return out


def _same(value: object, default: object) -> bool:
    if isinstance(value, list) and isinstance(default, str):
        return [float(v) for v in value] == [float(v) for v in default.split()]
    return value == default


def test_the_shipped_branching_task_is_built_through_the_dialogs_shown_nested_and_exported(page: Page) -> None:
    _build(page)
    items = page.locator("#steps > li")
    expect(items).to_have_count(7)
    expect(items.nth(0)).to_contain_text("Loop over step 1 while PartFound, at most 100 times")
    expect(items.nth(2)).to_have_class("branch-head depth-2")
    expect(items.nth(2)).to_contain_text(f"If step 1 ({_label(LOCALIZE)}) ends with PartFound:")
    expect(items.nth(5)).to_contain_text(f"If step 1 ({_label(LOCALIZE)}) ends with NoPartFound:")
    pick = page.locator("#steps li.step[data-place='0/PartFound/0']")
    expect(pick).to_have_class("step in-branch depth-2")
    expect(pick.locator(".step-no")).to_have_text("1.1")
    expect(pick).to_contain_text("pick pose ← part pose of localize")
    expect(page.locator("#steps li.step[data-place='0/NoPartFound/0'] .step-no")).to_have_text("1.3")
    expect(page.locator("#verdict .ok")).to_contain_text("Plausible")
    screenshot(page, "task-editor-branch-in-loop")
    with page.expect_download() as download:
        page.get_by_role("button", name="Export YAML").click()
    built = _task_file(download.value.path().read_text(encoding="utf-8"))
    shipped = _task_file(SHIPPED.read_text(encoding="utf-8"))
    assert built == {**shipped, "steps": _as_built(shipped["steps"])}  # type: ignore[arg-type]
    assert built["steps"][0]["loop"]["steps"][0]["on"]["PartFound"][0]["params"]["pick_pose"] == {
        "from": "localize", "output": "part_pose"}


def test_a_finding_in_a_branch_shows_at_its_row_with_its_path_and_the_branch_is_edited_and_removed(
        page: Page) -> None:
    _localize(page)
    _loop_until_empty(page)
    _open_branch(page, "PartFound")
    _pick_in_branch(page, "1.1")
    _pick_in_branch(page, "1.2")  # the gripper holds the part: a second pick cannot start
    page.locator("#branch-dialog").get_by_role("button", name="Save branch").click()
    second = page.locator("#steps li.step[data-place='0/PartFound/1']")
    finding = second.locator(".problem[data-kind='wrong_state']").first
    expect(finding.locator(".path")).to_have_text("loop iteration 1, branch PartFound at step 1")
    expect(finding).to_contain_text("device 'gripper' (role 'gripper') is in state 'closed'")
    expect(page.locator("#steps li.step[data-place='0'] .problem")).to_have_count(0)
    repairs = page.locator("#repair-list li.repair")
    kept = repairs.filter(has_not=page.locator(".unrolls")).first  # opening the gripper inside the branch
    expect(kept.locator(".apply")).to_be_enabled()
    written_out = repairs.filter(has=page.locator(".unrolls")).first  # the server says why it cannot keep the loop
    expect(written_out.locator(".unrolls")).to_contain_text("writes the task's loops and branches out step by step")
    expect(written_out.locator(".apply")).to_be_disabled()
    screenshot(page, "task-editor-branch-finding")
    page.get_by_role("button", name="Edit the PartFound branch of step 1").click()
    expect(page.locator("#branch-title")).to_have_text(
        f"Edit branch: If step 1 ({_label(LOCALIZE)}) ends with PartFound")
    expect(page.locator("#branch-steps li")).to_have_count(2)
    screenshot(page, "dialog-branch")
    page.get_by_role("button", name="Remove branch step 2 (pick)").click()
    _branch_step(page, "place", "step 1.2 in the PartFound branch of step 1")
    _save_step(page)
    page.locator("#branch-dialog").get_by_role("button", name="Save branch").click()
    expect(page.locator("#steps li.step")).to_have_count(3)
    expect(page.locator("#verdict .ok")).to_contain_text("Plausible")
    page.get_by_role("button", name="Remove the PartFound branch of step 1").click()
    expect(page.locator("#steps li.step")).to_have_count(1)
    expect(page.locator("#steps .branch-head")).to_have_count(0)


@pytest.mark.parametrize("served", [SimulatedBin(PARTS, SEED)], indirect=True)
def test_the_run_shows_the_branch_taken_after_each_localisation_and_succeeds(page: Page, served: Served) -> None:
    _build(page)
    expect(page.locator("#verdict .ok")).to_contain_text("Plausible")
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-status")).to_contain_text("succeeded", timeout=120_000)
    taken = page.locator("#run-branches li")
    expect(taken).to_have_count(PARTS + 1)
    for i in range(PARTS):
        expect(taken.nth(i)).to_have_text(f"iteration {i + 1} step 1 (localize) ended with PartFound: the PartFound "
                                          "branch taken, step 1.1 (pick) next")
    expect(taken.nth(PARTS)).to_have_text(f"iteration {PARTS + 1} step 1 (localize) ended with BinEmpty: the "
                                          "NoPartFound branch taken, step 1.3 (move-to) next")
    expect(page.locator("#run-loops")).to_contain_text(f"iteration {PARTS + 1}")
    screenshot(page, "run-branch-in-loop")
    assert served.hmi.source.sim.bin is not None and served.hmi.source.sim.bin.parts == []


def test_a_loop_goes_on_while_its_steps_report_an_outcome(page: Page) -> None:
    page.get_by_role("button", name=f"Add {_label('place')} to the task", exact=True).click()
    _save_step(page)
    _localize(page)
    page.get_by_role("button", name="Add loop").click()
    page.locator("#loop-last").select_option("0")
    expect(page.locator("#loop-while option")).to_have_text(["no step here ends with an outcome"])
    page.locator("#loop-first").select_option("1")
    page.locator("#loop-last").select_option("1")
    expect(page.locator("#loop-while option")).to_have_text(["whatever the steps report", *OUTCOMES])
    page.locator("#loop-while").select_option("PartFound")
    page.locator("#loop-max").fill("5")
    page.locator("#loop-dialog").get_by_role("button", name="Save loop").click()
    expect(page.locator("#steps .loop-head .loop-text")).to_have_text("Loop over step 2 while PartFound, at most 5 times")
    with page.expect_download() as download:
        page.get_by_role("button", name="Export YAML").click()
    built = yaml.safe_load(download.value.path().read_text(encoding="utf-8"))
    assert built["steps"][1] == {"loop": {"while": "PartFound", "max": 5, "steps": [
        {"name": "localize", "command": LOCALIZE, "params": {"exposure": 25}}]}}


NESTED = b"""\
task: nested
steps:
  - name: localize
    command: localize-part
    on:
      PartFound:
        - command: scan-bin
        - command: localize-part
          on:
            BinEmpty:
              - command: scan-bin
      BinEmpty:
        - command: scan-bin
  - command: scan-bin
"""


def test_an_imported_branch_in_a_branch_is_listed_as_written_and_a_loop_in_a_branch_is_refused(page: Page) -> None:
    page.locator("#import").set_input_files(files=[{"name": "nested.yaml", "mimeType": "application/yaml",
                                                    "buffer": NESTED}])
    expect(page.locator("#steps li.step")).to_have_count(6)
    numbers = page.locator("#steps li.step .step-no")
    expect(numbers).to_have_text(["1", "1.1", "1.2", "1.2.1", "1.3", "2"])
    expect(page.locator("#steps li.step[data-place='0/PartFound/1/BinEmpty/0']")).to_have_class(
        "step in-branch depth-2")
    expect(page.locator("#steps .branch-head .branch-text")).to_have_text([
        f"If step 1 ({_label(LOCALIZE)}) ends with PartFound:", f"If step 1.2 ({_label(LOCALIZE)}) ends with BinEmpty:",
        f"If step 1 ({_label(LOCALIZE)}) ends with BinEmpty:"])
    expect(page.locator("#steps li.step[data-place='0/PartFound/0'] .add-branch")).to_have_count(0)  # no outcome
    screenshot(page, "task-editor-nested-branches")
    page.get_by_role("button", name="Move step 1.1 (scan bin) down").click()
    expect(numbers).to_have_text(["1", "1.1", "1.1.1", "1.2", "1.3", "2"])
    page.get_by_role("button", name="Remove step 1.1.1 (scan bin)").click()  # the branch's only step: it goes
    expect(page.locator("#steps .branch-head")).to_have_count(2)
    expect(numbers).to_have_text(["1", "1.1", "1.2", "1.3", "2"])
    expect(page.locator("#verdict .ok, #verdict .bad")).to_be_visible()  # checked: no check is pending
    looped = NESTED.replace(b"        - command: scan-bin\n        - command: localize-part",
                            b"        - loop: {max: 2, steps: [{command: scan-bin}]}\n        - command: localize-part")
    page.locator("#import").set_input_files(files=[{"name": "looped.yaml", "mimeType": "application/yaml",
                                                    "buffer": looped}])
    expect(page.locator("#verdict .error")).to_have_text(
        "This task has a loop inside a branch: the editor builds loops of the task's steps only; edit that task file "
        "by hand.")
    expect(page.locator("#steps li.step")).to_have_count(5)  # the task as it was
    inner = service.builtin("tasks", "bin-picking-in-rounds.yaml").read_bytes()
    page.locator("#import").set_input_files(files=[{"name": "rounds.yaml", "mimeType": "application/yaml",
                                                    "buffer": inner}])
    expect(page.locator("#verdict .error")).to_have_text(
        "This task has a loop inside a loop: the editor builds loops of the task's steps only; edit that task file "
        "by hand.")
    expect(page.locator("#steps li.step")).to_have_count(5)  # not mangled: the task as it was


SLOW_GRIPPER = "gripper:delay-event:gripper_closed:1"
"""The simulated gripper reports closed a second late (within its 2 s timeout): time to watch the run."""


@pytest.mark.parametrize("served", [SLOW_GRIPPER], indirect=True)
def test_while_a_branch_runs_its_head_and_its_step_are_marked(page: Page) -> None:
    shipped = SHIPPED.read_text(encoding="utf-8").replace("max: 100", "max: 1")
    page.locator("#import").set_input_files(files=[{"name": "once.yaml", "mimeType": "application/yaml",
                                                    "buffer": shipped.encode()}])
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Start run").click()
    expect(page.locator("#run-states tr[data-device='gripper'] .badge")).to_have_text("closing")
    expect(page.locator("#steps li.step.running")).to_have_attribute("data-place", "0/PartFound/0")
    expect(page.locator("#steps .branch-head.running")).to_have_attribute("data-outcome", "PartFound")
    screenshot(page, "run-branch-in-progress")
    expect(page.locator("#run-status")).to_contain_text("succeeded")
    expect(page.locator("#steps .branch-head.running")).to_have_count(0)
