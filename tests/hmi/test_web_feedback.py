"""Issue 29, the page (real headless Chromium): a refused plug and a code generation are answered by their
buttons; the Why? tree names what each reason rests on in plain words and marks the branch that fails; a
cell that follows discovery offers no plug button at all."""

from __future__ import annotations

import socket
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
import uvicorn
from playwright.sync_api import Browser, Page, expect

from plugnproduce import service
from plugnproduce.hmi import ExecutorRunner, LiveCellSource, create_app
from plugnproduce.protocols.upnp import private_network
from tests.hmi.conftest import TOKEN, screenshot

expect.set_options(timeout=30_000)  # a bound, not a speed: CI runs the suite on a fully loaded machine


def test_a_refused_plug_is_said_next_to_the_plug_button(page: Page) -> None:
    form = page.locator("#plug-form")
    expect(form).to_be_visible()
    page.evaluate("""() => {  // a list gone stale: the device is no longer in the catalogue
        const select = document.querySelector('#plug-device');
        select.append(new Option('ghost', 'ghost'));
        select.value = 'ghost';
    }""")
    form.get_by_role("button", name="Plug in").click()
    status = form.locator("#plug-status")
    expect(status).to_contain_text("Not plugged in:")
    expect(status).to_contain_text("ghost")
    expect(status).to_be_visible()
    screenshot(page, "plug-refused")


def test_generate_code_says_what_it_did_next_to_its_button(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking.yaml")))
    expect(page.locator("#verdict .ok")).to_be_visible()
    page.get_by_role("button", name="Generate code").click()
    status = page.locator("#generate-status")
    expect(status).to_contain_text("Generated 5 charts (its program proved over every interleaving).")
    expect(status.get_by_role("link", name="See them under Charts")).to_have_attribute("href", "#charts")
    screenshot(page, "generate-status")
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking-invalid.yaml")))
    expect(page.locator("#verdict .bad")).to_be_visible()
    page.get_by_role("button", name="Generate code").click()
    expect(status.locator(".error")).to_contain_text("No code generated: step 2 (bin-pick)")


def test_the_why_tree_speaks_plain_words_and_marks_the_failing_branch(page: Page) -> None:
    page.get_by_role("button", name="Why is transport not offered?").click()
    why = page.locator("#why-transport")
    why.locator("details.derivation > summary").click()
    kinds = why.locator(".tree .kind")
    expect(kinds.first).to_be_visible()
    assert set(kinds.all_text_contents()) == {"rule", "ontology"}  # of every node, shown or folded
    failing = why.locator("li.node.fails")
    expect(failing).to_have_count(1)
    expect(failing.locator("> details > summary")).to_contain_text(
        "✗ why not: rule no device in cell 'bin-picking' has the skill 'can transport'")
    failing.locator("> details > summary").click()
    expect(failing.locator("li.node", has_text="requires the skill 'can transport'")).to_be_visible()
    screenshot(page, "why-not-plain-words")


def test_a_steps_why_marks_only_the_failing_branch(page: Page) -> None:
    page.locator("#import").set_input_files(str(service.builtin("tasks", "bin-picking-invalid.yaml")))
    problem = page.locator("#steps li.step[data-row='1'] .problem").first
    problem.get_by_role("button", name="Why?").click()
    tree = problem.locator(".why details.derivation")
    tree.locator("> summary").click()
    top = tree.locator("> ul.tree > li.node")
    expect(top.first).to_be_visible()
    failing = tree.locator("> ul.tree > li.node.fails")
    expect(failing).to_have_count(1)
    expect(failing).to_contain_text("✗ why not: rule device 'gripper' is not in a state role 'gripper' may start from")
    assert top.count() > 1  # the devices where they may start are shown, unmarked
    expect(tree.locator("> ul.tree > li.node:not(.fails) .fails-mark")).to_have_count(0)
    expect(tree).not_to_contain_text("ASP")
    screenshot(page, "why-step-failing-branch")


@pytest.fixture()
def discovered_page(browser: Browser, tmp_path: Path) -> Iterator[Page]:
    """The page over a cell that follows discovery (pnp serve without --sim), on a private SSDP network."""
    source = LiveCellSource(private_network(), search_timeout=0.5)
    app = create_app(source, ExecutorRunner(source, tmp_path / "runs"), TOKEN)
    sock = socket.create_server(("127.0.0.1", 0))
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on", ws="none",
                                           timeout_graceful_shutdown=1))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, name="hmi-live", daemon=True)
    thread.start()
    context = browser.new_context(viewport={"width": 1360, "height": 1000})
    pg = context.new_page()
    try:
        pg.goto(f"http://127.0.0.1:{sock.getsockname()[1]}/#token={TOKEN}")
        pg.wait_for_selector("body[data-ready='true']")
        yield pg
    finally:
        context.close()
        app.state.hub.close_streams()
        server.should_exit = True
        thread.join(10)
        sock.close()


def test_a_cell_that_follows_discovery_offers_no_plug_button(discovered_page: Page) -> None:
    page = discovered_page
    expect(page.locator("#devices-empty")).to_be_visible()
    expect(page.get_by_role("button", name="Plug in")).to_have_count(0)
    expect(page.locator("#plug-form")).to_be_hidden()
    page.get_by_role("button", name="Why is pick not offered?").click()
    why = page.locator("#why-pick")
    expect(why.locator(".counterfactuals li").first).to_be_visible()
    expect(why.locator(".counterfactuals button")).to_have_count(0)  # said, not offered as a click that fails
    screenshot(page, "discovered-cell-no-plug")
