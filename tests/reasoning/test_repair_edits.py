"""Every repair's edits say what its task does: a removed step is gone, a swapped pair runs swapped, an edited
step still runs; and a repair leaves no step stuck in a dead end (rules/repair.lp's constraints on pairs of edits
and on the repaired task's plausibility, seen in the next-best repairs a user is offered)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.model import Cell, Task
from plugnproduce.reasoning import Repair, RepairCosts
from tests.reasoning.conftest import task

TRANSPORT_LOCK = Path(__file__).parent.parent / "data" / "libraries" / "transport-lock"


def assert_edits_match_the_task(r: Repair, original: Task) -> None:
    """The repaired task is the original with exactly the repair's edits applied, step for step."""
    kinds = [e.kind for e in r.edits]
    removed = {e.step for e in r.edits if e.kind == "remove"}
    kept = [o for o in r.origins if o]
    assert sorted(kept) == [i for i in range(1, len(original.steps) + 1) if i not in removed], r.edits
    assert r.origins.count(0) == kinds.count("insert"), r.edits
    for e in r.edits:
        if e.kind == "swap":
            assert e.step is not None and kept.index(e.step + 1) < kept.index(e.step), r.edits
        if e.kind in ("reset", "rebind", "bind", "unbind"):
            assert e.step in kept, r.edits
    for position, origin in enumerate(r.origins):
        if origin:
            changed = any(e.step == origin and e.kind in ("reset", "rebind", "bind", "unbind") for e in r.edits)
            if not changed:
                assert r.task.steps[position].params == original.steps[origin - 1].params, r.edits


def pick_and_place(*kinds: str) -> Task:
    """A task of the shipped bin-picking task's steps: ``pick``/``place``, ``bad-pick`` (grip force 500 N, beyond
    the gripper's 140 N), ``bad-place`` (speed 500 %), ``loose-pick`` (a bin-pick that binds no role)."""
    pick, place = task("bin-picking").steps[:2]
    made = {"pick": pick, "place": place, "loose-pick": replace(pick, bind={}),
            "bad-pick": replace(pick, params={**pick.params, "grip_force": 500}),
            "bad-place": replace(place, params={**place.params, "speed": 500})}
    return Task("t", tuple(replace(made[k], index=n) for n, k in enumerate(kinds, start=1)), "t.yaml")


@pytest.mark.parametrize("kinds, costs", [
    (("pick", "pick", "place"), RepairCosts()),
    (("bad-pick", "pick", "place"), RepairCosts()),
    (("pick", "bad-pick", "place"), RepairCosts()),
    # the bad place must come after the next pick, and without it that pick has nothing to drop before the next:
    # resetting its value and swapping is a repair; "swap it, and remove it" while it still runs is not
    (("bad-place", "pick", "pick"), RepairCosts(reset=20)),
    # the bad pick must come before the place, and without it the place holds nothing: "swap them, and remove the
    # pick" while the pick still runs is not a repair
    (("place", "bad-pick"), RepairCosts()),
])
def test_every_next_best_repair_does_what_its_edits_say(cell: Cell, kinds: tuple[str, ...], costs: RepairCosts) -> None:
    bad = pick_and_place(*kinds)
    repairs = service.repair(bad, cell, top=12, costs=costs)
    assert len(repairs) >= 4
    for r in repairs:
        assert_edits_match_the_task(r, bad)
        assert service.check(r.task, cell).plausible, r.edits


BIND = "step {}: bind role '{}' to device '{}' (several devices fit)"


@pytest.mark.parametrize("extra, kinds, expected", [
    # the magnetic gripper can place but not bin-pick: only the places' gripper role is ambiguous
    ("magnetic-gripper", ("pick", "place") * 3, [(6.0, [BIND.format(f"{i} (place)", "gripper", "gripper") for i in (2, 4, 6)])]),
    # a second robot: the next-best repair moves with the SCARA, and binds each step once, to its own device
    ("scara", None, [(4.0, [BIND.format("1 (pick-and-place)", "robot", "robot"),
                                        BIND.format("2 (move-to)", "robot", "robot")]),
                                 (4.0, [BIND.format("1 (pick-and-place)", "robot", "robot"),
                                        BIND.format("2 (move-to)", "robot", "scara")])]),
    # the vacuum gripper can place but not bin-pick: the pick's gripper role is not ambiguous, though it is a place's
    ("vacuum-gripper", ("loose-pick", "place"), [(2.0, [BIND.format("2 (place)", "gripper", "gripper")])]),
])
def test_a_repair_binds_each_ambiguous_role_of_each_step_once_to_the_device_it_runs_with(
        cell: Cell, device, extra: str, kinds: tuple[str, ...] | None, expected: list) -> None:
    two = cell.with_device(device(extra))
    repairs = service.repair(pick_and_place(*kinds) if kinds else task("pick-and-place"), two, top=len(expected))
    assert [(r.cost, [e.text for e in r.edits]) for r in repairs] == expected
    for r in repairs:
        bound = {(e.step, e.role): e.device for e in r.edits if e.kind == "bind"}
        assert all(r.task.steps[i - 1].bind[role] == d for (i, role), d in bound.items())
        assert service.check(r.task, two).plausible


def test_an_inserted_command_binds_the_roles_several_devices_fit(cell: Cell, device) -> None:
    two = cell.with_device(device("vacuum-gripper"))  # both grippers can open: the inserted command names its own
    repairs = service.repair(pick_and_place("pick", "pick", "place"), two, top=3)
    best = repairs[0]
    assert [e.text for e in best.edits] == ["insert open-gripper before step 2 (bin-pick)",
                                            BIND.format("3 (place)", "gripper", "gripper")]
    assert [(st.command, st.bind.get("gripper")) for st in best.task.steps] == [
        ("bin-pick", "gripper"), ("open-gripper", "gripper"), ("bin-pick", "gripper"), ("place", "gripper")]
    assert all(service.check(r.task, two).plausible for r in repairs)


def test_a_gripper_locked_open_is_never_left_in_the_repaired_task() -> None:
    k = service.knowledge((TRANSPORT_LOCK,))
    close = service.task(TRANSPORT_LOCK / "tasks" / "close-gripper.yaml")
    locked = service.cell(TRANSPORT_LOCK / "cells" / "bin-picking-locked.yaml", k)
    repairs = service.repair(close, locked, service.catalogue(), top=3, knowledge=k)
    assert [(r.cost, [e.kind for e in r.edits]) for r in repairs] == [
        (4.0, ["remove"]), (7.18, ["add", "bind"]), (8.07, ["add", "bind", "reset"])]
    by_id = {d.id: d for d in service.catalogue()}
    for r in repairs:
        extended = locked
        for added in r.added_devices:
            extended = extended.with_device(by_id[added])
        assert service.check(r.task, extended, k).plausible, r.edits
        assert all(s.bind.get("gripper") != "locked-gripper" for s in r.task.steps)
