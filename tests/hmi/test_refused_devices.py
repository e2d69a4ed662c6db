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
