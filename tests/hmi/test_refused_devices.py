"""The page and the API list every device discovery refused, with its URL and reason, as ``pnp discover`` does."""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys

import httpx

from tests.discovery.hostile import HostileDevice
from tests.hmi.conftest import Hmi

WAIT = 60.0


async def test_a_refused_device_is_listed_by_the_api_with_its_url_and_reason_as_by_discover(
        client: httpx.AsyncClient, hmi: Hmi) -> None:
    with HostileDevice(hmi.source.network, "uuid:hostile-huge", "huge") as device:
        async with asyncio.timeout(WAIT):
            while not (refused := (await client.get("/api/cell")).json()["refused"]):
                await asyncio.sleep(0.1)
        env = {**os.environ, "PNP_SSDP_PORT": str(hmi.source.network.port)}
        command = [sys.executable, "-m", "plugnproduce", "discover", "--json", "--timeout", "60"]
        done = await asyncio.to_thread(subprocess.run, command, env=env, capture_output=True, text=True, timeout=120)
    assert [(r["udn"], r["url"]) for r in refused] == [(device.udn, device.location)]
    assert "4194304 bytes" in refused[0]["reason"]
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["refused"] == refused


def test_the_page_lists_a_refused_device_with_its_url_and_reason(page, served) -> None:  # type: ignore[no-untyped-def]
    from playwright.sync_api import expect

    from tests.hmi.conftest import screenshot

    with HostileDevice(served.hmi.source.network, "uuid:hostile-huge", "huge") as device:
        item = page.locator(f"#refused-list li[data-udn='{device.udn}']")
        expect(item).to_be_visible(timeout=60_000)
        expect(item).to_contain_text(f"{device.udn} at {device.location}: ")
        expect(item).to_contain_text("4194304 bytes")
        expect(page.locator("#devices tbody tr")).to_have_count(4)  # the honest devices stay
        screenshot(page, "cell-refused-device")
