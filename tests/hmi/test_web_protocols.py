"""The page's device table shows each device's protocol and the endpoint the controller reaches it at."""

from __future__ import annotations

import re

import httpx
from playwright.sync_api import Page, expect

from tests.hmi.conftest import AUTH, Served, screenshot
from tests.lines import WAIT

expect.set_options(timeout=WAIT * 1000)  # the suite's limit, not a speed: CI runs the suite on a loaded machine


def test_an_opc_ua_device_plugged_in_shows_its_protocol_and_opc_tcp_endpoint(page: Page, served: Served) -> None:
    robot = page.locator("#devices tr[data-device='robot'] td.protocol")
    expect(robot.locator(".proto")).to_have_text("XIRP")
    expect(robot.locator(".endpoint")).to_have_text(re.compile(r"^xirp://127\.0\.0\.1:\d+$"))
    expect(page.locator("#devices tr[data-device='sensor3d'] td.protocol .proto")).to_have_text("UPnP")
    httpx.post(f"{served.url}/api/cell/devices", json={"device": "screwdriver-ua"}, headers=AUTH,
               timeout=WAIT).raise_for_status()
    nutrunner = page.locator("#devices tr[data-device='screwdriver-ua'] td.protocol")
    expect(nutrunner.locator(".proto")).to_have_text("OPC UA")
    expect(nutrunner.locator(".endpoint")).to_have_text(
        re.compile(r"^opc\.tcp://127\.0\.0\.1:\d+/pnp/screwdriver-ua$"))
    screenshot(page, "cell-with-opc-ua-device")
