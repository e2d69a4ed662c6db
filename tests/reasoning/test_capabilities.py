"""Offered process commands of the bin-picking cell; unplugging and plugging grippers; why-not answers."""

from __future__ import annotations

from dataclasses import replace

from plugnproduce import service
from plugnproduce.description.model import Cell, DeviceDescription

GRIPPING = {"pick", "place", "pick-and-place", "bin-pick", "open-gripper", "close-gripper"}


def test_the_paper_cell_offers_pick_place_pick_and_place_and_bin_pick(cell: Cell) -> None:
    assert {"pick", "place", "pick-and-place", "bin-pick"} <= set(service.capabilities(cell).commands())


def test_every_valid_binding_is_listed(cell: Cell) -> None:
    caps = service.capabilities(cell, all_bindings=True)
    bin_pick = next(o for o in caps.offered if o.command == "bin-pick")
    assert bin_pick.bindings == ({"gripper": "gripper", "localizer": "binpicking-pc", "robot": "robot",
                                  "sensor": "sensor3d"},)


def test_a_second_gripper_doubles_the_bindings_of_pick(cell: Cell, vacuum_with_default: DeviceDescription) -> None:
    caps = service.capabilities(cell.with_device(vacuum_with_default), all_bindings=True)
    pick = next(o for o in caps.offered if o.command == "pick")
    assert sorted(b["gripper"] for b in pick.bindings) == ["gripper", "vacuum-gripper"]
    assert pick.binding_count == 2


def _offer(caps, command: str):
    return next(o for o in caps.offered if o.command == command)


def test_by_default_one_binding_is_shown_with_the_number_of_bindings_and_who_can_play_each_role(
        cell: Cell, device) -> None:
    two = cell.with_device(device("magnetic-gripper")).with_device(device("scara"))
    pick = _offer(service.capabilities(two), "pick")
    assert pick.bindings == ({"gripper": "gripper", "robot": "robot"},)
    assert pick.binding_count == 4
    assert pick.role_devices == {"gripper": ("gripper", "magnetic-gripper"), "robot": ("robot", "scara")}


def test_the_count_and_the_one_binding_agree_with_listing_them_all(cell: Cell, devices) -> None:
    big = Cell("big", tuple(replace(d, id=f"{d.id}-{k}") for k in range(3) for d in devices))
    default, listed = service.capabilities(big), service.capabilities(big, all_bindings=True)
    assert default.commands() == listed.commands()
    assert default.not_offered == listed.not_offered
    for few, every in zip(default.offered, listed.offered, strict=True):
        assert few.binding_count == len(every.bindings) == every.binding_count > 1
        assert few.bindings == every.bindings[:1]
        assert all(b[r] in few.role_devices[r] for b in every.bindings for r in b)


def test_unplugging_the_gripper_removes_every_process_with_a_gripping_role(cell: Cell) -> None:
    before = set(service.capabilities(cell).commands())
    after = set(service.capabilities(cell.without("gripper")).commands())
    assert before - after == GRIPPING


def test_the_reason_is_the_missing_can_grip(cell: Cell) -> None:
    ex = service.explain_process(cell.without("gripper"), "pick")
    assert not ex.offered
    (reason,) = ex.reasons
    assert reason.code == "no_skill"
    assert "pnp:CanGrip" in reason.text and "gripper" in reason.text
    assert "http://plugnproduce.org/ontology#CanGrip" in reason.iris
    assert reason.where[0].file.endswith("pick.ttl") and reason.where[0].line is not None


def test_a_vacuum_gripper_brings_back_what_its_gripping_role_can_do(cell: Cell,
                                                                   vacuum_with_default: DeviceDescription) -> None:
    swapped = cell.without("gripper").with_device(vacuum_with_default)
    assert GRIPPING <= set(service.capabilities(swapped).commands())


def test_a_vacuum_gripper_needing_a_vacuum_no_process_supplies_grips_nothing(cell: Cell, device) -> None:
    swapped = cell.without("gripper").with_device(device("vacuum-gripper"))
    caps = service.capabilities(swapped)
    assert set(caps.commands()) & GRIPPING == {"open-gripper", "place"}  # these never send SuctionOn
    pick = next(n for n in caps.not_offered if n.command == "pick")
    (reason,) = pick.reasons
    assert reason.code == "no_argument"
    assert "'vacuum-gripper'" in reason.text and "request SuctionOn" in reason.text and "pnp:Vacuum" in reason.text
    assert reason.where[0].file.endswith("vacuum-gripper.ttl") and reason.where[1].file.endswith(".scxml")


def test_a_device_lacking_a_state_is_explained_with_its_chart(cell: Cell, device) -> None:
    gripper = device("gripper")
    broken = DeviceDescription(**{**gripper.__dict__, "states": tuple(s for s in gripper.states if s.id != "closed"),
                                  "transitions": tuple(t for t in gripper.transitions if "closed" not in
                                                       (t.source, t.target))})
    ex = service.explain_process(Cell("broken", (broken, device("robot"))), "pick")
    assert [r.code for r in ex.reasons] == ["lacks_state"]
    assert "closed (pnp:Closed)" in ex.reasons[0].text
    assert ex.reasons[0].where[0].file.endswith("pick.scxml")


def test_a_state_out_of_order_is_explained_as_unreachable(cell: Cell, device) -> None:
    gripper = device("gripper")
    one_way = DeviceDescription(**{**gripper.__dict__,
                                   "transitions": tuple(t for t in gripper.transitions if t.target != "closing")})
    ex = service.explain_process(Cell("one-way", (one_way, device("robot"))), "pick")
    assert [r.code for r in ex.reasons] == ["unreachable"]
    assert "from state 'open'" in ex.reasons[0].text


def test_capabilities_of_an_empty_cell_are_a_result() -> None:
    caps = service.capabilities(Cell("empty", ()))
    assert caps.offered == () and all(n.reasons for n in caps.not_offered)
