"""Repair window by window: the same optimal cost as repairing the whole task at once, on random tasks; and the repair
users get (``pnp repair``, :func:`plugnproduce.reasoning.repair`): a task of at most ``WHOLE_UP_TO`` steps repaired
whole, a longer one window by window, every setting of the call (catalogue, costs, insertion slots, most insertions,
how many repairs) honoured both ways."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugnproduce import service
from plugnproduce.description.model import Cell, DeviceDescription, Step, Task
from plugnproduce.description.taskfile import parse_task
from plugnproduce.reasoning import Repair, RepairCosts
from plugnproduce.reasoning import repair as user_repair
from plugnproduce.reasoning.repairs import repairs, sideeffects, windows
from plugnproduce.reasoning.repairs.windows import Window
from tests.reasoning.faulty_tasks import faulty_task

KNOWLEDGE = service.knowledge()


def whole(task: Task, cell: Cell, catalogue: list[DeviceDescription] | None = None, top: int = 1) -> list:
    return repairs.repair(task, cell, KNOWLEDGE, catalogue, top=top)


def windowed(task: Task, cell: Cell, catalogue: list[DeviceDescription] | None = None, top: int = 1,
             margin: int = windows.MARGIN) -> list:
    return windows.windowed_repair(task, cell, KNOWLEDGE, catalogue, top=top,
                                   margin=margin)


@settings(max_examples=12, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6), pairs=st.integers(8, 40), faults=st.integers(1, 4), margin=st.sampled_from([0, 2]),
       varied=st.booleans())
def test_windowed_repair_costs_what_the_whole_task_optimum_costs(cell: Cell, seed: int, pairs: int, faults: int,
                                                                 margin: int, varied: bool) -> None:
    task = faulty_task(pairs, min(faults, pairs - 2), seed, varied=varied)
    best = windowed(task, cell, margin=margin)[0]
    assert best.cost == whole(task, cell)[0].cost
    assert service.check(best.task, cell).plausible


def test_when_swapping_is_cheaper_than_inserting_the_windows_widen_until_the_cost_settles(cell: Cell) -> None:
    costs = RepairCosts(insert=10, insert_per_role=1, remove=8, swap=1, rebind=1, reset=5)
    assert not windows.edits_stay_local(costs, KNOWLEDGE.processes)
    task = faulty_task(8, 1, 113371)  # with windows of the problem alone: remove a step (8), not swap two (1)
    best = windows.windowed_repair(task, cell, KNOWLEDGE, costs=costs, top=1,
                                   margin=0)[0]
    assert best.cost == repairs.repair(task, cell, KNOWLEDGE, costs=costs,
                                       top=1)[0].cost == 1


def test_the_default_costs_keep_edits_local() -> None:
    assert windows.edits_stay_local(RepairCosts(), KNOWLEDGE.processes)


@pytest.mark.parametrize("costs, local", [
    (RepairCosts(remove=2, swap=2, rebind=2), True),  # as dear as the cheapest insertion (open-gripper: 1 + 1 role)
    (RepairCosts(remove=1.9), False),
    (RepairCosts(swap=1.9), False),
    (RepairCosts(rebind=1.9), False),
])
def test_edits_stay_local_while_no_edit_is_cheaper_than_the_cheapest_insertion(costs: RepairCosts, local: bool) -> None:
    assert windows.edits_stay_local(costs, KNOWLEDGE.processes) is local


def test_with_no_process_to_insert_every_edit_stays_local() -> None:
    assert windows.edits_stay_local(RepairCosts(remove=0.5), ()) is True


def test_a_long_task_keeps_its_unbroken_steps_and_is_plausible_after(cell: Cell) -> None:
    task = faulty_task(300, 12, 7)
    best = windowed(task, cell)[0]
    assert service.check(best.task, cell).plausible
    edited = {e.step for e in best.edits}
    problems = {p.step for p in service.check(task, cell).problems}
    assert all(any(abs(s - p) <= 4 for p in problems) for s in edited)  # edits only near the problems


def test_the_next_best_repairs_are_distinct_and_no_cheaper(cell: Cell) -> None:
    task = faulty_task(30, 3, 3)
    found = windowed(task, cell, top=3)
    assert [r.rank for r in found] == [1, 2, 3]
    assert [r.cost for r in found] == sorted(r.cost for r in found)
    assert found[0].cost == whole(task, cell)[0].cost
    assert len({tuple(e.text for e in r.edits) for r in found}) == 3
    assert all(service.check(r.task, cell).plausible for r in found)


def test_a_step_rebound_in_a_window_names_its_new_device_in_the_repaired_task(cell: Cell) -> None:
    task = faulty_task(25, 2, 5, kinds=("absent",))  # places 20 and 42 bound to a SCARA the cell does not have
    best = windowed(task, cell)[0]
    assert [(e.kind, e.step, e.role, e.device) for e in best.edits] == [("rebind", 20, "robot", "robot"),
                                                                         ("rebind", 42, "robot", "robot")]
    assert [(n, st.bind) for n, st in enumerate(best.task.steps, start=1) if st.bind] == [
        (20, {"robot": "robot"}), (42, {"robot": "robot"})]


def _screws(task: Task, at: tuple[int, ...]) -> Task:
    steps = list(task.steps)
    for i in sorted(at, reverse=True):
        steps.insert(i, Step(0, "screw"))
    return Task(task.name, tuple(replace(s, index=n) for n, s in enumerate(steps, start=1)), task.file)


def test_one_device_bought_for_two_distant_windows_is_paid_once(cell: Cell, devices: list[DeviceDescription]) -> None:
    task = _screws(faulty_task(25, 1, 5), (6, 42))  # two screw steps far apart, no screwdriver in the cell
    best = windowed(task, cell, devices)[0]
    assert best.added_devices == ("screwdriver",)
    assert best.cost == whole(task, cell, devices)[0].cost
    assert service.check(best.task, cell.with_device(_by_id(devices, best.added_devices[0]))).plausible


def test_a_device_bought_in_one_window_enters_the_next_in_the_state_the_first_left_it(
        cell: Cell, devices: list[DeviceDescription]) -> None:
    """No gripper in the cell: a pick and, 25 robot moves later, a place. The gripper bought for both leaves the
    pick holding the part, so the place needs nothing more (no close-gripper inserted before it)."""
    pick, place = (replace(st, bind={}) for st in service.task(service.builtin("tasks", "bin-picking.yaml")).steps[:2])
    move = Step(0, "move-to", {}, {"target_pose": [0.4, 0, 0.3, 0, 180, 0], "speed": 50})
    steps = [move] * 10 + [pick] + [move] * 25 + [place] + [move] * 10
    task = Task("far", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "far.yaml")
    best = windowed(task, cell.without("gripper"), devices)[0]
    assert [e.kind for e in best.edits] == ["add"] and best.added_devices == ("gripper",)
    assert best.cost == whole(task, cell.without("gripper"), devices)[0].cost == 5.18


def _by_id(devices: list[DeviceDescription], name: str) -> DeviceDescription:
    return next(d for d in devices if d.id == name)


def test_a_short_task_is_repaired_whole(cell: Cell) -> None:
    task = faulty_task(10, 2, 1)
    assert len(task.steps) <= windows.WHOLE_UP_TO
    got = service.repair(task, cell, top=3)
    assert [(r.cost, [e.text for e in r.edits]) for r in got] == [
        (r.cost, [e.text for e in r.edits]) for r in whole(task, cell, top=3)]


@pytest.mark.parametrize("spans, margin, expected", [
    ([Window(10, 12)], 2, [Window(8, 14)]),
    ([Window(1, 1), Window(99, 100)], 3, [Window(1, 4), Window(96, 100)]),
    ([Window(10, 12), Window(17, 17)], 2, [Window(8, 19)]),  # 8-14 and 15-19 touch: one window
    ([Window(10, 12), Window(18, 18)], 2, [Window(8, 14), Window(16, 20)]),
])
def test_windows_widen_and_merge(spans: list[Window], margin: int, expected: list[Window]) -> None:
    assert windows.windows(spans, 100, margin) == expected


def test_a_long_task_is_repaired_in_a_cell_with_a_device_that_lacks_an_argument(cell: Cell, device) -> None:
    # the vacuum gripper needs a vacuum no gripping process supplies (missing_arg/5, a shown atom with no step):
    # the windowed repair took the first number of every shown atom it did not know as a problem's step
    with_vacuum = cell.with_device(device("vacuum-gripper"))
    task = faulty_task(30, 2, 7)
    assert len(task.steps) > windows.WHOLE_UP_TO
    best = service.repair(task, with_vacuum, top=1)[0]
    assert best.cost == whole(task, with_vacuum)[0].cost
    assert service.check(best.task, with_vacuum).plausible


@pytest.mark.parametrize("top", [3, 5])
def test_a_windows_further_repairs_solved_when_wanted_are_those_solved_at_once(
        cell: Cell, top: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each window's best two repairs are solved at once, the rest only for a window the k-best combinations reach:
    those are solved entering the window as it was entered then, and give the repairs all solved at once give."""
    task = faulty_task(60, 6, 3, varied=True)
    solved: list[int] = []
    optimise = windows.solver.optimise

    def counted(*args: object, **kwargs: object) -> object:
        solved.append(int(args[2]))  # type: ignore[call-overload]
        return optimise(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(windows.solver, "optimise", counted)
    later = windowed(task, cell, top=top)
    assert solved.count(windows.FIRST) >= 3 and solved.count(top) >= 1  # some windows asked again for all
    monkeypatch.setattr(windows, "FIRST", top)
    at_once = windowed(task, cell, top=top)
    assert [(r.cost, r.edits, r.task) for r in later] == [(r.cost, r.edits, r.task) for r in at_once]
    assert len({tuple(e.text for e in r.edits) for r in later}) == top  # distinct

NOT_DROPPED = ("move-to", "swap", "force", "absent", "unknown")
SHORT = faulty_task(20, 2, 0, kinds=NOT_DROPPED)
"""40 steps: the third-best repair of the whole task (insert a place) is not the windows' (remove the bin-pick)."""
LONG = faulty_task(24, 2, 3, kinds=NOT_DROPPED)
"""48 steps: the third-best repair of the windows (insert a pick) is not the whole task's (insert a place)."""
LONG_INSERT = faulty_task(24, 1, 3, kinds=("move-to",))
"""48 steps: best repaired by inserting an open-gripper, else by removing a bin-pick."""


def _answers(found: list[Repair]) -> list[tuple[float, list[str]]]:
    return [(r.cost, [e.text for e in r.edits]) for r in found]


def _inserts(found: list[Repair]) -> list[str]:
    return [e.text for r in found for e in r.edits if e.kind == "insert"]


def test_a_task_of_exactly_the_whole_limit_is_repaired_whole(cell: Cell) -> None:
    assert len(SHORT.steps) == windows.WHOLE_UP_TO
    got = _answers(service.repair(SHORT, cell, top=3))
    assert got == _answers(repairs.repair(SHORT, cell, KNOWLEDGE, top=3))
    assert got[2] == (4.0, ["insert place before step 28 (move-to)",
                            "step 29 (bin-pick): reset parameter grip_force to its default 40"])
    assert got != _answers(windows.windowed_repair(SHORT, cell, KNOWLEDGE, top=3))  # the two ways differ here


def test_a_longer_task_is_repaired_window_by_window(cell: Cell) -> None:
    assert len(LONG.steps) > windows.WHOLE_UP_TO
    got = _answers(service.repair(LONG, cell, top=3))
    assert got == _answers(windows.windowed_repair(LONG, cell, KNOWLEDGE, top=3))
    dropped = "step 18 (place): drop parameter grip_force (not declared)"
    assert got == [(4.0, [dropped, "swap step 40 (bin-pick) with step 41 (place)"]),
                   (5.0, [dropped, "insert open-gripper before step 40 (bin-pick)",
                          "insert close-gripper before step 42 (place)"]),
                   (6.0, [dropped, "insert open-gripper before step 40 (bin-pick)",
                          "insert pick before step 42 (place)"])]
    assert got != _answers(repairs.repair(LONG, cell, KNOWLEDGE, top=3))  # the two ways differ here


def test_three_repairs_unless_asked_for_another_number(cell: Cell) -> None:
    assert [r.rank for r in user_repair(SHORT, cell, KNOWLEDGE)] == [1, 2, 3]
    assert [r.rank for r in user_repair(LONG, cell, KNOWLEDGE)] == [1, 2, 3]
    assert [r.rank for r in windows.windowed_repair(LONG, cell, KNOWLEDGE)] == [1, 2, 3]


def test_no_insertion_when_none_is_allowed_short_or_long(cell: Cell) -> None:
    for task in (SHORT, LONG_INSERT):
        assert _inserts(windows.repair(task, cell, KNOWLEDGE, top=1))  # the best repair inserts a step
        found = windows.repair(task, cell, KNOWLEDGE, top=1, max_inserts=0)
        assert _inserts(found) == [] and found[0].cost == 4.0
        assert service.check(found[0].task, cell).plausible


def test_no_insertion_without_insertion_slots_short_or_long(cell: Cell) -> None:
    for task, removed in ((SHORT, "remove step 29 (bin-pick)"), (LONG_INSERT, "remove step 17 (bin-pick)")):
        found = windows.repair(task, cell, KNOWLEDGE, top=1, per_gap=0)
        assert _answers(found) == [(4.0, [removed])]


def test_the_users_costs_price_the_repair_short_or_long(cell: Cell) -> None:
    costs = RepairCosts(insert=7, reset=3)
    assert _answers(windows.repair(SHORT, cell, KNOWLEDGE, top=1, costs=costs)) == [
        (4.0, ["remove step 29 (bin-pick)"])]
    assert _answers(windows.repair(LONG, cell, KNOWLEDGE, top=1, costs=costs)) == [
        (6.0, ["step 18 (place): drop parameter grip_force (not declared)",
               "swap step 40 (bin-pick) with step 41 (place)"])]


def _with_screw(task: Task) -> Task:
    screws = "  - command: screw\n" * 2
    return parse_task(f"task: screwed\nsteps:\n{_steps(task)}{screws}".encode(), "screwed.yaml")


def _steps(task: Task) -> str:
    return "".join(f"  - command: {st.command}\n" for st in task.steps)


def test_a_device_of_the_catalogue_is_bought_short_or_long(cell: Cell, devices: list[DeviceDescription]) -> None:
    """No screwdriver in the cell: two screw steps at the end of a short and of a long plausible task (buying a
    screwdriver costs less than removing both)."""
    for pairs in (10, 24):
        task = _with_screw(faulty_task(pairs, 0, 1))
        [best] = service.repair(task, cell, devices, top=1)
        assert best.added_devices == ("screwdriver",) and best.cost == 5.14


LOOP = """  - loop:
      until: BinEmpty
      max: 100
      steps:
        - name: localize
          command: localize-part
          params: {exposure: 25}
        - command: pick
          params:
            pick_pose: {from: localize, output: part_pose}
            grip_force: 45
        - command: place
        - command: screw
"""


def test_a_long_task_keeps_its_loop_with_the_device_bought_for_it(cell: Cell, devices: list[DeviceDescription]
                                                                 ) -> None:
    """42 bin-pick and place steps, then a loop that screws: the screwdriver bought, the loop written as it was."""
    text = f"task: long-loop\nsteps:\n{_steps(faulty_task(21, 0, 1))}{LOOP}"
    task = parse_task(text.encode(), "long-loop.yaml")
    assert len(task.steps) > windows.WHOLE_UP_TO
    [best] = service.repair(task, cell, devices, top=1)
    assert best.added_devices == ("screwdriver",) and best.unrolls is None
    assert [(lp.entry, lp.first, lp.last) for lp in best.task.loops] == [(43, 47, 50)]
    assert service.check(best.task, cell.with_device(next(d for d in devices if d.id == "screwdriver"))).plausible


def test_a_window_with_a_single_repair_gives_that_one_however_many_are_asked(cell: Cell) -> None:
    """A grip force out of range, no insertion slots, the window the bin-pick alone: removing the bin-pick would
    leave the gripper open for the place after the window, so resetting the force is the only repair."""
    task = faulty_task(25, 1, 0, kinds=("force",))
    found = windows.windowed_repair(task, cell, KNOWLEDGE, top=3, per_gap=0, margin=0)
    assert _answers(found) == [(1.0, ["step 27 (bin-pick): reset parameter grip_force to its default 40"])]


def test_every_combination_of_the_windows_repairs_when_fewer_than_asked(cell: Cell) -> None:
    """Two places bound to a SCARA the cell lacks, no insertion slots: each window is repaired by rebinding its place
    or removing it with its bin-pick, so there are four repairs, whatever the number asked."""
    task = faulty_task(25, 2, 5, kinds=("absent",))
    found = windows.windowed_repair(task, cell, KNOWLEDGE, top=10, per_gap=0)
    assert [r.cost for r in found] == [4.0, 10.0, 10.0, 16.0]
    assert len({tuple(e.text for e in r.edits) for r in found}) == 4


def test_a_window_leaves_the_devices_as_the_steps_after_it_expect(cell: Cell, device) -> None:
    """Resetting the grip force dear, the window the bin-pick alone: removing the bin-pick (4) would leave the gripper
    open for the place after the window; the repair closes it as well (6), and the task is plausible (in a cell with
    a conveyor no step uses)."""
    with_conveyor = cell.with_device(device("conveyor"))
    task = faulty_task(25, 1, 0, kinds=("force",))
    costs = RepairCosts(reset=10)
    [best] = windows.windowed_repair(task, with_conveyor, KNOWLEDGE, top=1, costs=costs, margin=0)
    assert _answers([best]) == [(6.0, ["insert close-gripper before step 27 (bin-pick)", "remove step 27 (bin-pick)"])]
    assert service.check(best.task, with_conveyor).plausible


def test_a_long_task_plausible_as_written_needs_no_repair(cell: Cell) -> None:
    task = faulty_task(25, 0, 1)
    assert service.check(task, cell).plausible
    assert service.repair(task, cell, top=3) == []
    assert windows.windowed_repair(task, cell, KNOWLEDGE, top=3) == []


def test_the_next_best_repairs_with_a_catalogue_are_distinct_bought_or_not(cell: Cell,
                                                                         devices: list[DeviceDescription]) -> None:
    """Two screw steps far apart and a grip force out of range: buy a screwdriver, or remove both screws, or buy it
    and repair the force otherwise; each once."""
    task = _screws(faulty_task(25, 1, 5), (6, 42))
    found = windowed(task, cell, devices, top=3)
    assert [(r.cost, r.added_devices) for r in found] == [(6.14, ("screwdriver",)), (9.0, ()),
                                                          (11.14, ("screwdriver",))]
    assert len({tuple(e.text for e in r.edits) for r in found}) == 3


def test_a_problem_at_a_devices_first_use_is_repaired_in_a_long_task(cell: Cell) -> None:
    """The gripper's first use is a place (nothing picked): its problem's span starts at that step."""
    move = Step(0, "move-to", {}, {"target_pose": [0.4, 0, 0.3, 0, 180, 0], "speed": 50})
    place = Step(0, "place")
    steps = [move] * 20 + [place] + [move] * 25
    task = Task("first-use", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "first-use.yaml")
    assert len(task.steps) > windows.WHOLE_UP_TO
    found = service.repair(task, cell, top=2)
    assert _answers(found) == [(2.0, ["insert close-gripper before step 21 (place)"]),
                               (2.0, ["insert close-gripper before step 20 (move-to)"])]
    assert all(service.check(r.task, cell).plausible for r in found)


def test_a_purchase_paying_for_itself_only_over_two_windows_by_one_hundredth_is_made(
        cell: Cell, devices: list[DeviceDescription]) -> None:
    """Removing a screw step costs 1, a (dear) screwdriver 1.99 in all: worth buying for the two screw steps far apart,
    though in each window alone removing is cheaper."""
    screwdriver = replace(_by_id(devices, "screwdriver"), cost=15000)
    costs = RepairCosts(insert=0.5, insert_per_role=0.5, remove=1, swap=1, rebind=1, add_device=0.49)
    task = _screws(faulty_task(25, 0, 5), (6, 42))
    found = windows.windowed_repair(task, cell, KNOWLEDGE, [screwdriver], top=3, costs=costs)
    assert _answers(found) == [(1.99, ["add device 'screwdriver' (Electric screwdriver, price 15000) to the cell"]),
                               (2.0, ["remove step 7 (screw)", "remove step 44 (screw)"])]
    # the best alone: removing both screw steps (2) is dearer than the screwdriver (1.99) by one hundredth
    assert _answers(windows.windowed_repair(task, cell, KNOWLEDGE, [screwdriver], top=1, costs=costs)) == [
        (1.99, ["add device 'screwdriver' (Electric screwdriver, price 15000) to the cell"])]


def test_two_windows_buying_two_devices_buy_both(cell: Cell, devices: list[DeviceDescription]) -> None:
    """A screw step and, far from it, a machine-part step: each window buys its own device, the best repair both."""
    costs = RepairCosts(add_device=1, add_device_per_price=0)
    steps = list(faulty_task(25, 0, 5).steps)
    steps.insert(6, Step(0, "screw"))
    steps.insert(42, Step(0, "machine-part"))
    task = Task("two", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "two.yaml")
    found = windows.windowed_repair(task, cell, KNOWLEDGE, devices, top=3, costs=costs)
    assert [(r.cost, r.added_devices) for r in found] == [(2.0, ("cnc", "screwdriver")), (5.0, ("screwdriver",)),
                                                          (5.0, ("cnc",))]
    assert [e.text for e in found[1].edits] == [
        "add device 'screwdriver' (Electric screwdriver, price 1400) to the cell", "remove step 43 (machine-part)"]


@pytest.mark.parametrize("add_device, tried, bought", [
    (2.0, False, False),  # the device costs what the repair without it costs: not even priced window by window
    (1.01, True, False),  # with the force's reset (1) no purchase can cost less than 2: priced, not tried
    (0.99, True, True),  # 0.99 + 1 is cheaper than 2: tried and bought
])
def test_a_purchase_is_tried_only_when_it_can_pay_for_itself(cell: Cell, devices: list[DeviceDescription],
                                                             add_device: float, tried: bool, bought: bool,
                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """A grip force out of range (reset: 1) and, later, a screw step (remove: 1, or buy a screwdriver): the windows
    are solved with the screwdriver added only when the cheapest purchase plus what the windows cost with it nearly
    free is below the repair without it."""
    costs = RepairCosts(insert=0.5, insert_per_role=0.5, remove=1, swap=1, rebind=1, add_device=add_device,
                        add_device_per_price=0)
    steps = list(faulty_task(25, 1, 0, kinds=("force",)).steps)
    steps.insert(44, Step(0, "screw"))
    task = Task("force-screw", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "fs.yaml")
    priced: list[int] = []
    added: list[tuple[str, ...]] = []
    purchases, combined = windows._Solver.purchases, windows._Solver.combined
    monkeypatch.setattr(windows._Solver, "purchases", lambda self, *a: priced.append(1) or purchases(self, *a))
    monkeypatch.setattr(windows._Solver, "combined",
                        lambda self, w, a: added.append(tuple(d.id for d in a)) or combined(self, w, a))
    found = windows.windowed_repair(task, cell, KNOWLEDGE, [_by_id(devices, "screwdriver")], top=1, costs=costs)
    assert (bool(priced), [a for a in added if a]) == (tried, [("screwdriver",)] if bought else [])
    reset = "step 27 (bin-pick): reset parameter grip_force to its default 40"
    assert _answers(found) == ([(1.99, ["add device 'screwdriver' (Electric screwdriver, price 1400) to the cell", reset])]
                               if bought else [(2.0, [reset, "remove step 45 (screw)"])])


def test_a_device_priced_nearly_free_enters_the_next_window_as_the_first_left_it(
        cell: Cell, devices: list[DeviceDescription]) -> None:
    """No gripper, a pick and 25 moves later a place, removing a step costs 3: the gripper (5.18) is cheaper than
    removing both (6) only if, pricing the windows with the gripper nearly free, the place's window finds the gripper
    holding the part the pick's window left it with (else it would need a close-gripper too, and the purchase would
    seem unable to pay for itself)."""
    pick, place = (replace(st, bind={}) for st in service.task(service.builtin("tasks", "bin-picking.yaml")).steps[:2])
    move = Step(0, "move-to", {}, {"target_pose": [0.4, 0, 0.3, 0, 180, 0], "speed": 50})
    steps = [move] * 10 + [pick] + [move] * 25 + [place] + [move] * 10
    task = Task("far", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "far.yaml")
    found = windows.windowed_repair(task, cell.without("gripper"), KNOWLEDGE, [_by_id(devices, "gripper")], top=1,
                                    costs=RepairCosts(remove=3))
    assert _answers(found) == [(5.18, ["add device 'gripper' (Parallel gripper, price 1800) to the cell"])]


def test_a_step_inserted_in_a_window_is_the_only_new_step_of_the_repaired_task(cell: Cell) -> None:
    """The repaired task's steps keep their original positions (what the side effects of a repair are judged by),
    the open-gripper inserted before step 19 none."""
    [best] = windows.windowed_repair(LONG_INSERT, cell, KNOWLEDGE, top=1)
    assert _answers([best]) == [(2.0, ["insert open-gripper before step 19 (bin-pick)"])]
    assert best.origins == (*range(1, 19), 0, *range(19, 49))
    assert sideeffects.new_steps(LONG_INSERT, best.task, best.origins) == {19}
    written = [st.command for st in LONG_INSERT.steps]
    assert [st.command for st in best.task.steps] == [*written[:18], "open-gripper", *written[18:]]  # all kept
    assert [st.index for st in best.task.steps] == list(range(1, 50)) and best.task.name == LONG_INSERT.name


def test_a_value_beyond_the_devices_limit_far_from_other_problems_is_reset_saying_which_limit(cell: Cell) -> None:
    """48 steps: the bin-pick at 11 sends the gripper 10 N (within the process's range, below the 20 N the gripper
    takes: a problem of the device's limits, not of the encodings' check), the bin-pick at 41 a force beyond the
    process's own range. Both are reset, the first saying which limit of which device it broke; the repaired task is
    plausible."""
    steps = list(faulty_task(24, 0, 1).steps)
    steps[10] = replace(steps[10], params={"grip_force": 10})
    steps[40] = replace(steps[40], params={"grip_force": 150})
    task = Task("limits", tuple(steps), "limits.yaml")
    assert len(task.steps) > windows.WHOLE_UP_TO
    assert [(p.kind, p.step) for p in service.check(task, cell).problems] == [("device_limit", 11), ("too_high", 41)]
    found = service.repair(task, cell, top=1)
    assert _answers(found) == [(2.0, [
        "step 11 (bin-pick): reset parameter grip_force to its default 40 (device 'gripper' takes at least 20 N; "
        "the value is 10 N)", "step 41 (bin-pick): reset parameter grip_force to its default 40"])]
    assert service.check(found[0].task, cell).plausible


def test_windows_alike_but_for_a_pose_are_repaired_each_with_its_own_steps(cell: Cell) -> None:
    """A place done twice after one bin-pick, early in the task to the same pose, late to two poses; no insertion
    slots. Removing either of the first two places leads to the same task (one repair); removing either of the last
    two does not (two repairs), though both windows make the same facts (a pose is no number of the encodings)."""
    here, there = {"place_pose": [0.5, 0.1, 0.2, 0, 180, 0]}, {"place_pose": [0.5, -0.1, 0.2, 0, 180, 0]}
    steps = list(faulty_task(24, 0, 1).steps)
    steps[11] = replace(steps[11], params=here)
    steps.insert(12, steps[11])  # step 13: the same place again
    steps[38] = replace(steps[38], params=here)
    steps.insert(39, replace(steps[38], params=there))  # step 40: a place elsewhere
    task = Task("twice", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "twice.yaml")
    assert [(p.kind, p.step) for p in service.check(task, cell).problems] == [("wrong_state", 13), ("wrong_state", 40)]
    found = windows.windowed_repair(task, cell, KNOWLEDGE, top=2, per_gap=0)
    assert _answers(found) == [(8.0, ["remove step 12 (place)", "remove step 39 (place)"]),
                               (8.0, ["remove step 12 (place)", "remove step 40 (place)"])]
    assert [st.params for st in found[1].task.steps[36:39]] == [{}, here, {}]  # the place to the pose there removed


def test_a_device_a_window_last_uses_enters_a_later_window_as_the_repair_left_it(cell: Cell) -> None:
    """A close-gripper with a force out of range (its reset dear: removed instead, the gripper left open) and, 20 moves
    later, a close-gripper bound to a gripper the cell lacks. The gripper's last use is the first window's last step;
    the second window rebinds its close-gripper to the gripper, open as the first window left it (not closed, as the
    task as written would have left it), so nothing more is needed."""
    move = Step(0, "move-to", {}, {"target_pose": [0.4, 0, 0.3, 0, 180, 0], "speed": 50})
    steps = [move] * 20 + [Step(0, "close-gripper", {}, {"grip_force": 500})] + [move] * 20 + [
        Step(0, "close-gripper", {"gripper": "gripper2"}, {"grip_force": 40})] + [move] * 5
    task = Task("two-closes", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "two-closes.yaml")
    found = windows.windowed_repair(task, cell, KNOWLEDGE, top=2, costs=RepairCosts(reset=10), margin=0)
    assert _answers(found) == [
        (6.0, ["remove step 21 (close-gripper)",
               "step 42 (close-gripper): bind role 'gripper' to device 'gripper' instead of 'gripper2'"]),
        (8.0, ["remove step 21 (close-gripper)", "remove step 42 (close-gripper)"])]
    assert all(service.check(r.task, cell).plausible for r in found)


def test_a_long_task_whose_only_problem_is_a_devices_limit_is_repaired_window_by_window(cell: Cell) -> None:
    """48 steps, the bin-pick at 11 sending the gripper 10 N (it takes at least 20 N): no problem of the encodings'
    check, so it is the device's limit alone that makes the task one to repair window by window."""
    steps = list(faulty_task(24, 0, 1).steps)
    steps[10] = replace(steps[10], params={"grip_force": 10})
    task = Task("limit", tuple(steps), "limit.yaml")
    got = _answers(service.repair(task, cell, top=3))
    assert got == [(1.0, ["step 11 (bin-pick): reset parameter grip_force to its default 40 (device 'gripper' takes "
                          "at least 20 N; the value is 10 N)"]),
                   (6.0, ["remove step 11 (bin-pick)", "insert close-gripper before step 12 (place)"]),
                   (7.0, ["remove step 11 (bin-pick)", "insert pick before step 12 (place)"])]
    assert got != _answers(repairs.repair(task, cell, KNOWLEDGE, top=3))  # the whole task's third: the pick before 11


def test_a_value_in_a_unit_of_another_quantity_far_from_other_problems_is_reset(cell: Cell) -> None:
    """48 steps: the bin-pick at 11 grips with "40 kg" (no force), the bin-pick at 41 with a force beyond the process's
    range. The windows see the value as written, so both are reset and the repaired task is plausible."""
    steps = list(faulty_task(24, 0, 1).steps)
    steps[10] = replace(steps[10], params={"grip_force": "40 kg"})
    steps[40] = replace(steps[40], params={"grip_force": 150})
    task = Task("kilograms", tuple(steps), "kilograms.yaml")
    assert [(p.kind, p.step) for p in service.check(task, cell).problems] == [("bad_unit", 11), ("too_high", 41)]
    found = service.repair(task, cell, top=1)
    assert _answers(found) == [(2.0, ["step 11 (bin-pick): reset parameter grip_force to its default 40",
                                      "step 41 (bin-pick): reset parameter grip_force to its default 40"])]
    assert service.check(found[0].task, cell).plausible


def test_a_problem_spans_back_to_the_devices_previous_use(cell: Cell) -> None:
    """A bin-pick and, six moves later, another (the gripper still closed): the open-gripper may go anywhere after the
    first bin-pick, so the window reaches back to it and every such place is a repair of its own."""
    pick = replace(service.task(service.builtin("tasks", "bin-picking.yaml")).steps[0], bind={})
    move = Step(0, "move-to", {}, {"target_pose": [0.4, 0, 0.3, 0, 180, 0], "speed": 50})
    steps = [move] * 15 + [pick] + [move] * 6 + [pick] + [move] * 20
    task = Task("again", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "again.yaml")
    assert [(p.kind, p.step) for p in service.check(task, cell).problems] == [("wrong_state", 23)]
    found = _answers(service.repair(task, cell, top=8))
    assert found[0] == (2.0, ["insert open-gripper before step 23 (bin-pick)"])
    assert sorted(found[:7]) == [(2.0, [f"insert open-gripper before step {i} ({'move-to' if i < 23 else 'bin-pick'})"])
                                 for i in range(17, 24)]
    assert found[7] == (3.0, ["insert place before step 23 (bin-pick)"])


def test_a_long_task_whose_only_problem_no_edit_cures_gets_the_whole_tasks_answer(cell: Cell) -> None:
    """49 steps, the last taking its pose from a step no step is named: the encodings find nothing to repair, so the
    answer is the whole-task repair's, however many repairs are asked for."""
    body = "".join(f"  - command: {st.command}\n" for st in faulty_task(24, 0, 1).steps)
    text = f"task: linked\nsteps:\n{body}  - command: pick\n    params:\n      pick_pose: {{from: nowhere, output: part_pose}}\n"
    task = parse_task(text.encode(), "linked.yaml")
    assert [(p.kind, p.step) for p in service.check(task, cell).problems] == [("bad_link", 49)]
    for top in (1, 3):
        assert _answers(service.repair(task, cell, top=top)) == _answers(repairs.repair(task, cell, KNOWLEDGE, top=top))


def test_a_long_task_done_in_rounds_keeps_its_rounds_description_and_file_where_the_repair_keeps_them_alike(
        cell: Cell) -> None:
    """Twelve bin-picks and places done twice (48 steps), the third bin-pick of a round gripping too hard: the best
    repair resets it in both rounds, so its task is still one round done twice; the next repairs a round otherwise."""
    one_round = "".join("  - command: bin-pick\n" + ("    params: {grip_force: 150}\n" if i == 2 else "")
                        + "  - command: place\n" for i in range(12))
    text = f"task: rounds\ndescription: Twelve parts, twice\nrepeat: 2\nsteps:\n{one_round}"
    task = parse_task(text.encode(), "rounds.yaml")
    assert len(task.steps) == 48 and task.repeat == 2
    found = service.repair(task, cell, top=2)
    assert [(r.cost, r.task.repeat, r.task.description, r.task.file, len(r.task.steps)) for r in found] == [
        (2.0, 2, "Twelve parts, twice", "rounds.yaml", 48), (7.0, 1, "Twelve parts, twice", "rounds.yaml", 48)]
    assert found[0].task.one_round() == tuple(replace(st, params={}) if st.index == 5 else st
                                              for st in task.one_round())


def test_without_margin_a_problem_at_the_first_step_is_repaired_in_a_window_of_that_step_alone(cell: Cell) -> None:
    """The first bin-pick grips too hard, no margin: the window is step 1 alone, so besides the reset the only repair
    removes it and, before it, makes the gripper hold a located part for the place after it (the place is outside)."""
    steps = list(faulty_task(24, 0, 1).steps)
    steps[0] = replace(steps[0], params={"grip_force": 150})
    task = Task("first", tuple(steps), "first.yaml")
    found = windows.windowed_repair(task, cell, KNOWLEDGE, top=3, margin=0)
    assert _answers(found) == [
        (1.0, ["step 1 (bin-pick): reset parameter grip_force to its default 40"]),
        (10.0, ["insert localize-part before step 1 (bin-pick)", "insert pick before step 1 (bin-pick)",
                "remove step 1 (bin-pick)"])]
    assert all(service.check(r.task, cell).plausible for r in found)


@pytest.mark.parametrize("first, margins, answer", [
    (2, [2, 4, 8], (2.0, ["swap step 45 (bin-pick) with step 46 (place)",
                          "swap step 47 (bin-pick) with step 48 (place)"])),
    (0, [0, 1], (8.0, ["remove step 43 (bin-pick)"])),  # no margin: one step more, then the cost settles
])
def test_when_edits_do_not_stay_local_the_margins_double_until_the_cost_settles(
        cell: Cell, first: int, margins: list[int], answer: tuple[float, list[str]],
        monkeypatch: pytest.MonkeyPatch) -> None:
    costs = RepairCosts(insert=10, insert_per_role=1, remove=8, swap=1, rebind=1, reset=5)
    seen: list[int] = []
    widen = windows.windows
    monkeypatch.setattr(windows, "windows", lambda spans, n, margin: seen.append(margin) or widen(spans, n, margin))
    found = windows.windowed_repair(faulty_task(24, 1, 113371), cell, KNOWLEDGE, costs=costs, top=1, margin=first)
    assert (seen, _answers(found)) == (margins, [answer])


def test_a_long_task_whose_windows_cover_it_is_repaired_whole(cell: Cell, monkeypatch: pytest.MonkeyPatch) -> None:
    """42 steps with a fault in every pair but the first and the last: the windows merge into the whole task, which is
    then repaired as a short task is (one whole-task repair), not as one window."""
    task = faulty_task(21, 19, 0, kinds=NOT_DROPPED)
    assert len(task.steps) > windows.WHOLE_UP_TO
    expected = _answers(repairs.repair(task, cell, KNOWLEDGE, top=2))
    wholes: list[int] = []
    whole_repair = repairs.repair
    monkeypatch.setattr(repairs, "repair", lambda *a, **k: wholes.append(1) or whole_repair(*a, **k))
    monkeypatch.setattr(windows._Solver, "best", lambda *a: pytest.fail("solved window by window"))
    assert _answers(windows.windowed_repair(task, cell, KNOWLEDGE, top=2)) == expected and wholes == [1]
    no_slots = _answers(whole_repair(task, cell, KNOWLEDGE, top=1, per_gap=0))  # no step inserted
    assert _answers(windows.windowed_repair(task, cell, KNOWLEDGE, top=1, per_gap=0)) == no_slots != expected[:1]


def test_a_long_task_covered_by_its_windows_is_repaired_whole_with_the_users_catalogue_and_costs(
        cell: Cell, devices: list[DeviceDescription]) -> None:
    """42 steps in a cell without a gripper, which every step needs: the windows cover the task, and the whole-task
    repair buys a gripper at the user's prices (2 per device and a thousandth of its price)."""
    found = windows.windowed_repair(faulty_task(21, 0, 1), cell.without("gripper"), KNOWLEDGE, devices, top=2,
                                    costs=RepairCosts(add_device=2, add_device_per_price=0.001))
    assert _answers(found) == [(2.7, ["add device 'magnetic-gripper' (Magnetic gripper, price 700) to the cell"]),
                               (3.8, ["add device 'gripper' (Parallel gripper, price 1800) to the cell"])]


def test_a_long_task_whose_only_problem_is_a_stuck_device_is_repaired_window_by_window(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """45 moves and, at 31, a close-gripper in a cell whose gripper is delivered locked open (the transport-lock
    library, written outside the package): its stuck start state is a problem of the encodings' own check, so the
    task is repaired window by window, not handed whole to the whole-task repair."""
    library = Path(__file__).parent.parent / "data" / "libraries" / "transport-lock"
    k = service.knowledge((library,))
    cell = service.cell(library / "cells" / "bin-picking-locked.yaml", k)
    move = Step(0, "move-to", {}, {"target_pose": [0.4, 0, 0.3, 0, 180, 0], "speed": 50})
    steps = [move] * 30 + list(service.task(library / "tasks" / "close-gripper.yaml").steps) + [move] * 14
    task = Task("locked", tuple(replace(st, index=n) for n, st in enumerate(steps, start=1)), "locked.yaml")
    assert len(task.steps) > windows.WHOLE_UP_TO
    assert [(p.kind, p.step) for p in service.check(task, cell, k).problems] == [("stuck", 31)]
    monkeypatch.setattr(repairs, "repair", lambda *a, **kw: pytest.fail("repaired whole, not window by window"))
    found = service.repair(task, cell, top=3, knowledge=k)
    assert _answers(found) == [(4.0, ["remove step 31 (close-gripper)"])]
    assert service.check(found[0].task, cell, k).plausible
