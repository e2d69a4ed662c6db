"""The order of equally cheap purchases that need three devices, and the candidate sets the search looks at for
them: a library of five one-skill devices (two grippers and two cameras at equal prices, one arm) for the three
roles of one process, none of which the empty configuration fills."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.batch import BatchRow, Configuration, purchases
from tests.reasoning.conftest import write
from tests.reasoning.test_batch import STATES, TRIO, TRIO_TTL

DEVICES = (("grip-a", "CanGrip", 1), ("grip-b", "CanGrip", 1), ("cam-a", "CanSense3D", 3), ("cam-b", "CanSense3D", 3),
           ("arm", "CanMove", 5))
"""Name, skill and cost: each device plays one role of the trio process (grip, sense, move)."""

CHEAPEST = ("arm+cam-a+grip-a=9", "arm+cam-b+grip-a=9", "arm+cam-a+grip-b=9", "arm+cam-b+grip-b=9")
"""Every purchase fills each role once, with three devices at 9: equally cheap and equally many, they come in the
catalogue's order of the cheapest devices (grip-a before grip-b, then cam-a before cam-b)."""


def _one_skill(library: Path, name: str, skill: str, cost: int) -> None:
    """A device of one skill whose chart goes between the two states the skill needs, by a request each."""
    (a, ca), (b, cb) = STATES[skill]
    (library / "devices" / f"{name}.scxml").write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<scxml xmlns="http://www.w3.org/2005/07/scxml" '
        f'xmlns:pnp="http://plugnproduce.org/ontology#"\n       version="1.0" name="{name}" initial="{a}">\n'
        f'  <state id="{a}" pnp:concept="{ca}">\n    <transition event="xirp.request.Next" target="{b}"/>\n'
        f'  </state>\n  <state id="{b}" pnp:concept="{cb}">\n    <transition event="xirp.request.Next" target="{a}"/>\n'
        "  </state>\n</scxml>\n", encoding="utf-8")
    (library / "devices" / f"{name}.ttl").write_text(
        f"@prefix pnp: <http://plugnproduce.org/ontology#> .\n@prefix dev: <http://plugnproduce.org/devices/> .\n"
        f"dev:{name} a pnp:Robot ; pnp:hasSkill pnp:{skill} ; pnp:protocol pnp:XIRP ;\n"
        f'    pnp:endpoint "xirp://127.0.0.1:0" ; pnp:stateChart <{name}.scxml> ; pnp:commandTimeout 2.0 ;\n'
        f"    pnp:cost {cost} .\n", encoding="utf-8")


def _empty_cell(tmp_path: Path, top: int) -> BatchRow:
    library = tmp_path / "library"
    (library / "processes").mkdir(parents=True)
    (library / "processes" / "trio.scxml").write_text(TRIO, encoding="utf-8")
    (library / "processes" / "trio.ttl").write_text(TRIO_TTL, encoding="utf-8")
    (library / "devices").mkdir()
    for name, skill, price in DEVICES:
        _one_skill(library, name, skill, price)
    k = service.knowledge((library,))
    own = [d for d in k.devices if d.id in {name for name, _, _ in DEVICES}]
    the_task = service.task(write(tmp_path, "trio.yaml", "task: trio\nsteps:\n  - command: trio\n"))
    (row,) = service.batch([Configuration("empty", ())], own, [the_task], workers=1, knowledge=k, top=top)
    return row


@pytest.mark.parametrize("top", [1, 2, 4])
def test_equally_cheap_purchases_of_three_devices_come_in_catalogue_order(tmp_path: Path, top: int) -> None:
    row = _empty_cell(tmp_path, top)
    assert row.outcome == "buy" and row.plausible == ()
    assert row.to_csv()[-1] == " | ".join(CHEAPEST[:top])
    assert row.to_json()["purchase"] == {"options": [
        {"add": option.split("=")[0].split("+"), "cost": 9} for option in CHEAPEST[:top]]}


@pytest.mark.parametrize("limit, found", [(19, 1), (21, 3), (22, 4)])
def test_the_search_never_grows_a_set_that_fills_a_role_twice(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, limit: int, found: int) -> None:
    """No set holding both grippers or both cameras can be extended into a purchase, so the search looks at such a
    set but grows none: the empty set, the 15 sets of one or two devices and the two sets of a gripper and both
    cameras (7) come before the four purchases (9), so 22 candidate sets give all four and 19 the first. Grown,
    the sets of both grippers and a camera (5) or the arm (7), and of both grippers and both cameras (8), would
    come first too, and the first purchase would need 23."""
    monkeypatch.setattr(purchases, "LIMIT", limit)
    row = _empty_cell(tmp_path, 4)
    assert row.purchase is not None and row.purchase.text() == " | ".join(CHEAPEST[:found])
