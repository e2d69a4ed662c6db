"""A UPnP client nobody here wrote finds a simulated device and drives it: async-upnp-client's own command line
(``upnp-client``, installed with the library) searches by SSDP on loopback, reads the device's description and
calls its actions over SOAP, as any control point would.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.protocols.upnp import SERVICE_TYPE, private_network
from tests.lines import WAIT
from tests.processes import started, stop

CELL = str(service.builtin("cells", "bin-picking.yaml"))


def upnp_client() -> str:
    beside = Path(sys.executable).with_name("upnp-client")
    found = str(beside) if beside.exists() else shutil.which("upnp-client")
    assert found is not None, "async-upnp-client installs the upnp-client command"
    return found


@pytest.fixture
def cell(tmp_path: Path) -> Iterator[tuple[int, dict[str, str]]]:
    """``pnp sim up`` of the bin-picking cell on a private SSDP port: that port and each device's URL it prints."""
    port = private_network().port
    state, log = tmp_path / "control.json", tmp_path / "sim.log"
    env = {**os.environ, "PNP_SSDP_PORT": str(port)}
    env.pop("PNP_INTERFACE", None)
    with log.open("w") as out, started([sys.executable, "-m", "plugnproduce", "sim", "up", CELL, "--state-file",
                                        str(state)], env=env, stdout=out, stderr=subprocess.STDOUT) as up:
        deadline = time.monotonic() + WAIT
        while not state.exists():  # written once the devices are announced
            assert up.poll() is None, log.read_text()
            assert time.monotonic() < deadline, "pnp sim up did not come up"
            time.sleep(0.05)
        urls = {words[0]: words[2] for words in map(str.split, log.read_text().splitlines())
                if len(words) == 3 and words[1] in ("upnp", "xirp")}
        yield port, urls
        stop(up)


def client(*args: str) -> list[dict[str, object]]:
    """``upnp-client ARGS``: each JSON line it prints."""
    result = subprocess.run([upnp_client(), "--timeout", "10", *args], capture_output=True, text=True,
                            timeout=5 * WAIT)
    assert result.returncode == 0, result.stderr
    return [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]


def test_upnp_client_finds_the_camera_and_drives_its_chart(cell: tuple[int, dict[str, str]]) -> None:
    port, urls = cell
    answers = client("search", "--bind", "127.0.0.1", "--target", "239.255.255.250", "--target_port", str(port),
                     "--search_target", SERVICE_TYPE)
    found = {a["location"] for a in answers if a.get("ST") == SERVICE_TYPE and a.get("_host") == "127.0.0.1"}
    assert urls["sensor3d"] in found and urls["binpicking-pc"] in found, (urls, answers)
    camera = urls["sensor3d"]

    def state() -> object:
        (answer,) = client("call-action", camera, "DeviceControl/GetDeviceState")
        return answer["out_parameters"]["State"]  # type: ignore[index]

    assert state() == "ready"
    (captured,) = client("call-action", camera, "DeviceControl/Capture", "Exposure=20")
    assert captured["out_parameters"] == {"Result": "accepted"}
    deadline = time.monotonic() + WAIT
    while (now := state()) != "captured":  # the chart passes through capturing on its own
        assert now == "capturing" and time.monotonic() < deadline, now
