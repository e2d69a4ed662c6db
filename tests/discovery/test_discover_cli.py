"""``pnp discover`` says how long it searched and what may be missing, and waits for the devices it is told of."""

from __future__ import annotations

import json
import re
from pathlib import Path

from tests.discovery.test_slow_devices import CELL, env, pnp, simulated_cell  # noqa: F401 - fixtures

FOUR = ["binpicking-pc", "gripper", "robot", "sensor3d"]


def test_discover_says_how_long_it_searched_and_that_late_devices_may_be_missing(
        simulated_cell, env: dict[str, str]) -> None:  # noqa: F811
    found = pnp(env, "discover", "--timeout", "120")
    assert found.returncode == 0, found.stderr
    last = found.stdout.splitlines()[-1]
    assert re.fullmatch(r"searched \d+\.\d s \(until no new device for 2 s\); devices that answer later may be "
                        r"missing \(--expect N or --cell CELL waits for them\)", last), last


def test_discover_with_the_cell_waits_for_its_devices(simulated_cell, env: dict[str, str]) -> None:  # noqa: F811
    found = pnp(env, "discover", "--json", "--cell", CELL, "--timeout", "120")
    assert found.returncode == 0, found.stderr
    answer = json.loads(found.stdout)
    assert sorted(d["id"] for d in answer["devices"]) == FOUR
    assert answer["missing"] == [] and answer["summary"].endswith("every expected device answered")


def test_discover_exits_1_naming_the_devices_of_the_cell_it_did_not_find(env: dict[str, str]) -> None:  # noqa: F811
    found = pnp(env, "discover", "--cell", CELL, "--timeout", "1")  # nothing runs on this private network
    assert found.returncode == 1
    assert re.fullmatch(r"error: missing after \d+\.\d s of search \(--timeout 1\): robot, gripper, sensor3d, "
                     r"binpicking-pc\n", found.stderr), found.stderr


def test_discover_expecting_more_devices_than_answer_exits_1(simulated_cell, env: dict[str, str]) -> None:  # noqa: F811
    found = pnp(env, "discover", "--json", "--expect", "5", "--timeout", "5")
    assert found.returncode == 1
    answer = json.loads(found.stdout)
    ids = [d["id"] for d in answer["devices"]]
    assert set(ids) <= set(FOUR)  # all four on any machine but one too loaded to answer in 5 s
    assert answer["missing"] == [f"{5 - len(ids)} of 5 device(s)"]


def test_discover_with_a_cell_file_that_is_not_there_is_bad_input(tmp_path: Path, env: dict[str, str]) -> None:  # noqa: F811
    found = pnp(env, "discover", "--cell", str(tmp_path / "nope.yaml"))
    assert found.returncode == 2 and len(found.stderr.splitlines()) == 1, found.stderr


def test_discover_watch_prints_each_refusal_with_its_url_as_it_happens(env: dict[str, str]) -> None:  # noqa: F811
    import subprocess
    import sys

    from plugnproduce.protocols.upnp import SsdpNetwork
    from tests.discovery.hostile import HostileDevice
    from tests.lines import Lines

    watch = subprocess.Popen([sys.executable, "-m", "plugnproduce", "discover", "--json", "--watch", "--timeout",
                              "1", "--settle", "0.5"], env=env, text=True, stdout=subprocess.PIPE)
    lines = Lines(watch.stdout)
    try:
        assert json.loads(lines.next())["devices"] == []  # the private network is empty at first
        with HostileDevice(SsdpNetwork(port=int(env["PNP_SSDP_PORT"])), "uuid:hostile-huge", "huge") as device:
            change = json.loads(lines.next())
        assert (change["change"], change["device"], change["url"]) == ("refused", device.udn, device.location)
        assert "4194304 bytes" in change["reason"]
    finally:
        watch.terminate()
        watch.wait(timeout=60)
        lines.rest()
        assert watch.stdout is not None
        watch.stdout.close()
