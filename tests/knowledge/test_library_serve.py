"""``pnp serve`` with a library from ``PNP_LIBRARY``: the HMI offers, lists and plugs in its terms."""

from __future__ import annotations

import httpx

from tests.hmi.test_serve_command import _start, _stop
from tests.knowledge.test_machine_tending import CELL, MT


def test_serve_honours_the_library() -> None:
    proc, out, lines = _start("--sim", "--cell", str(CELL), env={"PNP_LIBRARY": str(MT)})
    try:
        url = lines[0].rsplit(" ", 1)[1]
        assert httpx.get(url + "api/cell").json()["name"] == "machine-tending"
        processes = {p["command"] for p in httpx.get(url + "api/processes").json()}
        assert {"open-door", "load-machine", "machine"} <= processes
        catalogue = {d["id"] for d in httpx.get(url + "api/catalogue").json()}
        assert {"mt-cnc", "gripper"} <= catalogue
    finally:
        _stop(proc, out)
