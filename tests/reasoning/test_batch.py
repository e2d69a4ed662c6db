"""Batch feasibility of many configurations: offered processes, plausible tasks, cheapest purchases."""

from __future__ import annotations

import itertools
import json
import random
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.batch import BatchRow, Configuration, batches, engine, generate, purchases, read_configurations
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.errors import DescriptionError
from plugnproduce.reasoning import CheckResult
from tests.reasoning.conftest import DESCRIPTIONS, task, write

PAPER = ("binpicking-pc", "gripper", "robot", "sensor3d")
LIBRARY = Path(__file__).parent.parent / "data" / "libraries" / "machine-tending"


def tasks() -> list[Task]:
    return [task("bin-picking"), task("pick-and-place")]


def rows(configs: list[Configuration], workers: int = 1, top: int = 1, catalogue: list[DeviceDescription] | None = None):
    return list(service.batch(configs, catalogue or service.catalogue(), tasks(), workers=workers, top=top))


def cost(*ids: str) -> int:
    return sum(round(d.cost) for d in service.catalogue() if d.id in ids)


def test_the_paper_cell_runs_both_tasks_and_needs_no_purchase() -> None:
    (row,) = rows([Configuration("paper", PAPER)])
    assert {"pick", "place", "bin-pick"} <= set(row.offered)
    assert row.plausible == ("bin-picking", "pick-and-place") and row.purchase is None


def test_the_cheapest_device_to_add_is_named_with_its_cost() -> None:
    (row,) = rows([Configuration("no-gripper", ("binpicking-pc", "robot", "sensor3d"))])
    assert row.plausible == ()
    assert row.purchase is not None and row.purchase.options == ((("gripper",), cost("gripper")),)
    assert row.to_json()["purchase"] == {"options": [{"add": ["gripper"], "cost": cost("gripper")}]}


def test_two_missing_devices_are_bought_together() -> None:
    (row,) = rows([Configuration("sensing-only", ("binpicking-pc", "sensor3d"))])
    assert row.purchase is not None
    assert row.purchase.options[0] == (("gripper", "robot"), cost("gripper", "robot"))


WITHIN_EVERY_ROBOT = (  # within the scara's reach and the cobot's speed
    "task: pick-and-place\nsteps:\n  - command: pick-and-place\n    params:\n"
    "      pick_pose: [0.35, 0.15, 0.04, 0, 180, 0]\n      place_pose: [0.45, -0.25, 0.08, 0, 180, 0]\n"
    "      retract_pose: [0.30, 0.00, 0.30, 0, 180, 0]\n      grip_force: 30\n"
    "  - command: move-to\n    params: {target_pose: [0.30, 0.00, 0.50, 0, 180, 0], speed: 50}\n")


def _gripper_only(tmp_path: Path, text: str, top: int) -> BatchRow:
    (row,) = service.batch([Configuration("gripper-only", ("gripper",))], None,
                           [service.task(write(tmp_path, "task.yaml", text))], workers=1, top=top)
    return row


def test_alternatives_come_cheapest_first(tmp_path: Path) -> None:
    row = _gripper_only(tmp_path, WITHIN_EVERY_ROBOT, 3)
    assert row.purchase is not None
    assert row.purchase.options == ((("scara",), cost("scara")), (("cobot",), cost("cobot")),
                                    (("robot",), cost("robot")))
    assert cost("scara") < cost("cobot") < cost("robot")
    assert row.to_csv()[-1] == f"scara={cost('scara')} | cobot={cost('cobot')} | robot={cost('robot')}"


@pytest.mark.parametrize("top", [1, 2])
def test_only_the_top_cheapest_alternatives_are_given(tmp_path: Path, top: int) -> None:
    row = _gripper_only(tmp_path, WITHIN_EVERY_ROBOT, top)
    assert row.purchase is not None
    assert row.purchase.options == ((("scara",), cost("scara")), (("cobot",), cost("cobot")))[:top]


@pytest.mark.parametrize("limit, bought", [(1, None), (2, "scara")])
def test_the_search_for_a_purchase_stops_after_its_limit_of_candidate_sets(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, limit: int, bought: str | None) -> None:
    """The candidates in order: the empty set (which fills no role), then the scara, the cheapest robot."""
    monkeypatch.setattr(purchases, "LIMIT", limit)
    row = _gripper_only(tmp_path, WITHIN_EVERY_ROBOT, 1)
    assert row.purchase is not None
    if bought is None:
        assert row.purchase.to_json() == {"options": [], "impossible": "no purchase found among the first 1 "
                                                                         "candidate sets (search stopped)"}
    else:
        assert row.purchase.options == (((bought,), cost(bought)),)


def test_a_search_that_would_end_without_a_purchase_still_stops_at_its_limit(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(purchases, "LIMIT", 2)
    row = _gripper_only(tmp_path, FAR, 1)
    assert row.outcome == "impossible" and row.purchase is not None
    assert row.purchase.impossible == "no purchase found among the first 2 candidate sets (search stopped)"


def test_the_csv_purchase_column_names_each_set_with_its_cost_or_what_to_do_instead() -> None:
    configs = [Configuration("paper", PAPER), Configuration("no-gripper", ("binpicking-pc", "robot", "sensor3d")),
               Configuration("sensing-only", ("binpicking-pc", "sensor3d")),
               Configuration("two-grippers", ("gripper", "magnetic-gripper", "robot"))]
    assert [r.to_csv()[-1] for r in rows(configs)] == [
        "", f"gripper={cost('gripper')}", f"gripper+robot={cost('gripper', 'robot')}",
        "ambiguous: step 2 of bin-picking: several devices can play role gripper; bind step 2's role gripper to one "
        "of them"]


FAR = ("task: far\nsteps:\n  - command: pick-and-place\n    params:\n"
       "      pick_pose: [0.35, 0.15, 0.04, 0, 180, 0]\n      place_pose: [1.48, 0.0, 0.08, 0, 180, 0]\n"
       "      retract_pose: [0.30, 0.00, 0.30, 0, 180, 0]\n      grip_force: 30\n")
"""A place 1.48 m from the robot's base: beyond every catalogue robot's reach (the scara's 0.6 m is the first tried)."""


@pytest.mark.parametrize("devices, added", [(("gripper",), "scara"),
                                            (("binpicking-pc", "sensor3d"), "magnetic-gripper+scara")])
def test_when_no_set_of_catalogue_devices_helps_the_answer_names_the_cheapest_one_tried(
        tmp_path: Path, devices: tuple[str, ...], added: str) -> None:
    far = service.task(write(tmp_path, "far.yaml", FAR))
    (row,) = service.batch([Configuration("c", devices)], None, [far], workers=1, top=3)
    why = (f"no set of catalogue devices makes every task plausible; e.g. adding {added}: step 1 of far: device "
           "scara (role robot) refuses a value sent to it by its own limits: parameter place_pose = "
           "[1.48, 0.0, 0.08, 0, 180, 0] goes with request MoveTo, which reaches at most 0.6 m from its base; the "
           "pose is 1.48 m away")
    assert row.outcome == "impossible" and row.to_json()["purchase"] == {"options": [], "impossible": why}
    assert row.to_csv()[-1] == f"impossible: {why}"


def test_a_robot_whose_own_limits_refuse_the_tasks_values_is_not_bought() -> None:
    (row,) = service.batch([Configuration("gripper-only", ("gripper",))], None, [task("pick-and-place")],
                           workers=1, top=3)
    assert row.purchase is not None  # the scara cannot reach the place pose, the cobot goes at most 60 %
    assert row.purchase.options == ((("robot",), cost("robot")),)


def test_no_purchase_when_the_catalogue_lacks_a_skill_and_the_reason_names_it() -> None:
    small = [d for d in service.catalogue() if d.id in ("robot", "sensor3d", "binpicking-pc")]
    (row,) = service.batch([Configuration("no-grippers-to-buy", ("robot",))], small, [task("pick-and-place")],
                           workers=1)
    assert row.purchase is not None and row.purchase.options == ()
    assert row.purchase.impossible is not None
    assert "no device can play role gripper" in row.purchase.impossible and "CanGrip" in row.purchase.impossible


def test_an_ambiguous_binding_is_not_impossible_and_says_which_role_to_bind() -> None:
    (row,) = rows([Configuration("two-grippers", ("gripper", "magnetic-gripper", "robot"))])
    assert row.outcome == "ambiguous" and row.purchase is not None
    assert row.purchase.options == () and row.purchase.impossible is None
    assert row.purchase.ambiguous == ("step 2 of bin-picking: several devices can play role gripper; "
                                      "bind step 2's role gripper to one of them")
    assert row.to_json()["purchase"] == {"options": [], "ambiguous": row.purchase.ambiguous}


def test_no_purchase_is_offered_for_a_configuration_whose_role_is_ambiguous() -> None:
    """Buying the missing robot would leave the gripper role ambiguous: binding comes first, not a purchase."""
    (row,) = service.batch([Configuration("grippers-only", ("gripper", "magnetic-gripper"))], None,
                           [task("pick-and-place")], workers=1)
    assert row.outcome == "ambiguous" and row.purchase is not None and row.purchase.options == ()
    assert "bind step 1's role gripper" in (row.purchase.ambiguous or "")


def test_an_ambiguous_role_of_a_task_with_loops_and_branches_is_not_impossible() -> None:
    """The check picks one binding and then finds a branch leaving the gripper differently: a consequence of the
    role left open, which binding it may cure."""
    (row,) = service.batch([Configuration("two-grippers", ("gripper", "magnetic-gripper", "robot"))], None,
                           [task("bin-picking-then-home")], workers=1)
    assert row.outcome == "ambiguous" and row.purchase is not None and row.purchase.impossible is None
    assert "role gripper; bind step 3's role gripper" in (row.purchase.ambiguous or "")


def test_a_limit_no_binding_cures_stays_impossible_beside_an_ambiguous_role() -> None:
    (row,) = service.batch([Configuration("slow-cobot", ("cobot", "gripper", "magnetic-gripper"))], None,
                           [task("pick-and-place")], workers=1)
    assert row.outcome == "impossible" and row.purchase is not None and row.purchase.ambiguous is None
    assert row.purchase.impossible == (
        "step 2 of pick-and-place: device cobot (role robot) refuses a value sent to it by its own limits: "
        "parameter speed = 100 % goes with request MoveTo, which takes at most 60 %; the value is 100 %; "
        "adding devices cannot cure it")


def test_a_value_refused_by_a_devices_limits_is_named_with_its_parameter() -> None:
    (row,) = service.batch([Configuration("scara", ("gripper", "scara"))], None, [task("pick-and-place")], workers=1)
    assert row.purchase is not None and row.purchase.impossible is not None
    assert ("device scara (role robot) refuses a value sent to it by its own limits: parameter place_pose = "
            "[0.55, -0.25, 0.08, 0, 180, 0] goes with request MoveTo, which reaches at most 0.6 m from its base; "
            "the pose is 0.609 m away; parameter retract_pose (its default) = '0.60 -0.20 0.30 0 180 0'"
            ) in row.purchase.impossible


def test_a_value_refused_in_a_task_with_loops_and_branches_is_named_as_the_check_names_it() -> None:
    (row,) = service.batch([Configuration("scara", ("gripper", "scara"))], None, [task("bin-picking-then-home")],
                           workers=1)
    assert row.purchase is not None and row.purchase.impossible is not None
    assert row.purchase.impossible.startswith(
        "step 3 of bin-picking-then-home: device scara (role robot) refuses a value sent to it by its own limits: "
        "parameter place_pose = [0.6, -0.2, 0.1, 0, 180, 0] goes to device 'scara' with request MoveTo, which "
        "reaches at most 0.6 m from its base; the pose is 0.64 m away")


def test_the_report_tallies_each_outcome() -> None:
    configs = [Configuration("paper", PAPER), Configuration("no-gripper", ("binpicking-pc", "robot", "sensor3d")),
               Configuration("two-grippers", ("gripper", "magnetic-gripper", "robot")),
               Configuration("scara", ("binpicking-pc", "gripper", "scara", "sensor3d"))]
    tally: dict[str, int] = {}
    text = "".join(service.batch_report(configs, None, tasks(), workers=1, tally=tally))
    assert [json.loads(line)["config"] for line in text.splitlines()] == [c.name for c in configs]
    assert [r.outcome for r in rows(configs)] == ["plausible", "buy", "ambiguous", "impossible"]
    assert tally == {"plausible": 1, "buy": 1, "ambiguous": 1, "impossible": 1}


def _reasoner(configs: list[Configuration], the_tasks: list[Task],
              k: service.Knowledge) -> list[tuple[tuple[str, ...], tuple[str, ...]]]:
    by_id = {d.id: d for d in k.devices}
    out = []
    for c in configs:
        cell = Cell(c.name, tuple(by_id[d] for d in c.devices))
        out.append((tuple(service.capabilities(cell, k).commands()),
                    tuple(t.name for t in the_tasks if service.check(t, cell, k).plausible)))
    return out


def _around(k: service.Knowledge, prefix: str, count: int) -> list[Configuration]:
    """Configurations that hold most of the devices whose ids start with ``prefix``, and a few others."""
    rng = random.Random(7)
    own = sorted(d.id for d in k.devices if d.id.startswith(prefix))
    others = sorted(d.id for d in k.devices if not d.id.startswith(prefix))
    return [Configuration(f"a{n}", tuple(rng.sample(own, rng.randint(len(own) // 2, len(own)))
                                         + rng.sample(others, rng.randint(0, 2)))) for n in range(count)]


@pytest.mark.parametrize("library", [None, LIBRARY], ids=["built-in", "machine-tending"])
def test_answers_agree_with_the_full_reasoner_on_random_configurations(library: Path | None) -> None:
    k = service.knowledge((library,) if library else ())
    the_tasks = ([service.task(p) for p in sorted((library / "tasks").glob("*.yaml"))] if library
                 else [*tasks(), task("bin-picking-invalid")])
    configs = list(generate(list(k.devices), 100, (0, 7), seed=11)) + _around(k, "mt-", 60)
    found = list(service.batch(configs, list(k.devices), list(the_tasks), workers=1, knowledge=k))
    assert [(r.offered, r.plausible) for r in found] == _reasoner(configs, the_tasks, k)
    assert any(r.plausible for r in found) and any(not r.plausible for r in found)


LOCALIZE = """  - command: localize-part
    bind: {sensor: sensor3d, localizer: binpicking-pc}
    params: {exposure: 25, part_type: bracket}
    on:
"""


def test_a_task_with_branches_is_answered_on_every_path_as_check_answers_it(tmp_path: Path) -> None:
    """Read in file order, the branch steps below look like one straight line: the first task (the gripper closed
    only when no part is found, so the two ways on leave it differently) would pass, the second (closed either
    way, twice in a row as written) would not; the check decides path by path, and so does the batch."""
    one_way = write(tmp_path, "one.yaml", "task: close-when-empty\nsteps:\n" + LOCALIZE
                    + "      NoPartFound:\n        - command: close-gripper\n")
    either_way = write(tmp_path, "either.yaml", "task: close-either-way\nsteps:\n" + LOCALIZE
                       + "      PartFound:\n        - command: close-gripper\n"
                       + "      NoPartFound:\n        - command: close-gripper\n")
    the_tasks = [service.task(one_way), service.task(either_way)]
    (row,) = service.batch([Configuration("paper", PAPER)], service.catalogue(), the_tasks, workers=1)
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    assert row.plausible == tuple(t.name for t in the_tasks if service.check(t, cell).plausible) == ("close-either-way",)
    assert row.purchase is not None and row.purchase.impossible == (
        "step 2 of close-when-empty: a branch leaves device gripper in another state than the other ways on from its "
        "step; adding devices cannot cure it")


@pytest.mark.parametrize("name", ["bin-picking-until-empty", "bin-picking-then-home", "bin-picking-in-rounds"])
def test_shipped_tasks_with_loops_branches_and_links_are_answered_as_check_answers_them(name: str) -> None:
    """Around the paper's cell (devices taken away, others added): the batch's answer is the check's, and the
    cheapest purchase makes the task plausible."""
    k = service.knowledge()
    rng = random.Random(name)
    others = sorted(d.id for d in k.devices if d.id not in PAPER)
    configs = [Configuration(f"c{n}", tuple(rng.sample(PAPER, rng.randint(2, 4)) + rng.sample(others, rng.randint(0, 3))))
               for n in range(12)]
    the_task = task(name)
    found = list(service.batch(configs, list(k.devices), [the_task], workers=1, knowledge=k))
    assert [r.plausible for r in found] == [p for _, p in _reasoner(configs, [the_task], k)]
    assert any(r.plausible for r in found) and any(not r.plausible for r in found)
    by_id = {d.id: d for d in k.devices}
    for config, row in zip(configs, found, strict=True):
        if row.purchase is not None and row.purchase.options:
            added = row.purchase.options[0][0]
            cell = Cell("bought", tuple(by_id[d] for d in (*config.devices, *added)))
            assert service.check(the_task, cell, k).plausible, (config, added)


def test_purchases_are_the_cheapest_sets_an_exhaustive_search_finds() -> None:
    catalogue = service.catalogue()
    e = engine(catalogue, tasks(), service.knowledge(), top=3)
    devices = e.feasibility.abilities.devices
    costs = e.feasibility.abilities.costs
    rng = random.Random(5)
    several = 0
    for n in range(150):
        config = Configuration(f"r{n}", tuple(rng.sample(devices, rng.randint(0, 4))))
        mask = e.mask(config)
        row = e.row(config)
        if row.purchase is None:
            assert len(row.plausible) == 2
            continue
        free = [i for i in range(len(devices)) if not mask >> i & 1]
        plausible = {frozenset(s) for size in range(1, 5) for s in itertools.combinations(free, size)
                     if len(e.feasibility.plausible(mask | sum(1 << i for i in s))) == 2}
        minimal = [s for s in plausible if not any(o < s for o in plausible)]  # no device in it superfluous
        works = sorted((sum(costs[i] for i in s), len(s), tuple(sorted(devices[i] for i in s))) for s in minimal)
        assert [(k, len(a)) for a, k in row.purchase.options] == [(k, m) for k, m, _ in works[:3]], config
        assert all((k, len(a), a) in works for a, k in row.purchase.options)
        several += bool(row.purchase.options) and len(row.purchase.options[0][0]) >= 2
    assert several >= 5  # the sample holds configurations that miss two devices or more


def test_two_workers_give_the_same_rows_as_one() -> None:
    configs = list(generate(service.catalogue(), 5000, (2, 5), seed=3))
    k = service.knowledge()
    by_workers = list(batches.batch(configs, service.catalogue(), tasks(), k, workers=2,
                                    chunk=500, solo=1000))
    assert by_workers == rows(configs, workers=1)


def test_workers_start_only_for_work_large_enough_to_repay_them(monkeypatch: pytest.MonkeyPatch) -> None:
    started: list[int] = []

    class Counted(batches.ProcessPoolExecutor):
        def __init__(self, workers: int, **kwargs: object) -> None:
            started.append(workers)
            super().__init__(workers, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(batches, "ProcessPoolExecutor", Counted)
    k = service.knowledge()
    configs = list(generate(service.catalogue(), 3000, (2, 5), seed=4))
    small = list(batches.batch(configs, service.catalogue(), tasks(), k, workers=2,
                               chunk=500, solo=3000))
    assert started == [] and len(small) == 3000
    large = list(batches.batch(configs, service.catalogue(), tasks(), k, workers=2,
                               chunk=500, solo=2000))
    assert started == [2] and large == small


def test_generation_is_deterministic_and_sized() -> None:
    a = list(generate(service.catalogue(), 50, (2, 6), seed=1))
    assert a == list(generate(service.catalogue(), 50, (2, 6), seed=1))
    assert all(2 <= len(c.devices) <= 6 and len(set(c.devices)) == len(c.devices) for c in a)


def test_configurations_from_jsonl_and_csv(tmp_path: Path) -> None:
    jsonl = write(tmp_path, "c.jsonl", '{"config": "a", "devices": ["robot", "gripper"]}\n\n')
    table = write(tmp_path, "c.csv", "config,devices\na,robot gripper\n")
    assert list(read_configurations(jsonl)) == list(read_configurations(table)) == [
        Configuration("a", ("robot", "gripper"))]


def test_configurations_stream_a_bad_line_is_found_when_it_is_reached(tmp_path: Path) -> None:
    bad = write(tmp_path, "c.jsonl", '{"config": "a", "devices": ["robot"]}\n{"config": "b"}\n')
    configs = read_configurations(bad)
    assert next(configs).name == "a"
    with pytest.raises(DescriptionError) as err:
        next(configs)
    assert err.value.line == 2 and err.value.file == str(bad)


def test_an_unknown_device_is_bad_input_at_its_line(tmp_path: Path) -> None:
    path = write(tmp_path, "c.jsonl", '{"config": "a", "devices": ["robot"]}\n{"config": "x", "devices": ["hoverboard"]}\n')
    with pytest.raises(DescriptionError, match="hoverboard") as err:
        list(service.batch(path, DESCRIPTIONS / "devices", tasks(), workers=1))
    assert err.value.location_message().startswith(f"{path}:2:")


def test_the_report_text_is_each_row_as_json() -> None:
    configs = list(generate(service.catalogue(), 400, (0, 7), seed=8))
    text = "".join(service.batch_report(configs, None, tasks(), workers=1, top=2))
    assert text == "".join(json.dumps(r.to_json()) + "\n" for r in rows(configs, top=2))



@pytest.mark.parametrize("speed, kind", [("0.5", "too_low"), ("101", "too_high")])
def test_a_value_outside_the_process_range_is_implausible_in_the_batch_as_in_check(tmp_path: Path, speed: str,
                                                                                    kind: str) -> None:
    the_task = service.task(write(
        tmp_path, "pick-and-place.yaml",
        "task: pick-and-place\nsteps:\n  - command: pick-and-place\n    params:\n"
        "      pick_pose: [0.35, 0.15, 0.04, 0, 180, 0]\n      place_pose: [0.45, -0.25, 0.08, 0, 180, 0]\n"
        f"      retract_pose: [0.30, 0.00, 0.30, 0, 180, 0]\n      grip_force: 30\n      speed: {speed}\n"))
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    checked = service.check(the_task, service.cell(DESCRIPTIONS / "cells" / "bin-picking.yaml"))
    assert [p.kind for p in checked.problems] == [kind]
    assert row.plausible == () and not checked.plausible


CLOSE_TWICE = ("task: close-twice\nsteps:\n  - command: close-gripper\n    params: {grip_force: 30}\n"
               "  - command: close-gripper\n    params: {grip_force: 30}\n")


def test_a_device_left_in_a_state_its_next_role_cannot_start_from_is_named_as_check_names_it(tmp_path: Path) -> None:
    """The second close finds the gripper closed: the batch says so as check does (wrong state, not stuck), and no
    purchase cures it."""
    the_task = service.task(write(tmp_path, "close-twice.yaml", CLOSE_TWICE))
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    [problem] = service.check(the_task, cell).problems
    assert (problem.step, problem.kind, problem.device) == (2, "wrong_state", "gripper")
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.options == ()
    assert row.purchase.impossible == ("step 2 of close-twice: device gripper is not in the state role gripper "
                                       "starts from; adding devices cannot cure it")


def _jammed_robot(library: Path) -> None:
    """The built-in robot as ``jammed-robot``, written outside the package: from each state it idles in, the first
    MoveTo of its chart (in the order code generation ranks them) goes to a state it never leaves."""
    builtin = service.builtin("devices")
    (library / "devices").mkdir(parents=True)
    ttl = (builtin / "robot.ttl").read_text(encoding="utf-8").replace("dev:robot", "dev:jammed-robot")
    (library / "devices" / "jammed-robot.ttl").write_text(ttl.replace("<robot.scxml>", "<jammed-robot.scxml>"),
                                                          encoding="utf-8")
    chart = (builtin / "robot.scxml").read_text(encoding="utf-8").replace('name="robot"', 'name="jammed-robot"')
    jam = '    <transition event="xirp.request.MoveTo" target="blocked" pnp:accepts="TargetPose Speed"/>\n'
    for state in ("home", "at_pose"):
        at = chart.index("\n", chart.index(f'<state id="{state}"')) + 1
        chart = chart[:at] + jam + chart[at:]
    chart = chart.replace("</scxml>", '  <state id="blocked" pnp:concept="Moving"/>\n</scxml>')
    (library / "devices" / "jammed-robot.scxml").write_text(chart, encoding="utf-8")


def test_a_device_that_can_walk_a_role_only_by_a_way_its_chart_does_not_take_is_stuck_in_the_batch_as_in_check(
        tmp_path: Path) -> None:
    """The jammed robot has the skill and a way through the robot role's region, so it may play it; but the way its
    chart takes ends where it never leaves, from every state it starts in. Check says stuck; so does the batch,
    step 2 (the move after it) included, and no purchase cures it."""
    _jammed_robot(tmp_path)
    k = service.knowledge((tmp_path,))
    the_task = task("pick-and-place")
    for devices, problems in ((("jammed-robot", "gripper"), [(1, "stuck", "jammed-robot")]),
                              (("robot", "gripper"), [])):
        cell = Cell("c", tuple(d for d in k.devices if d.id in devices))
        assert [(p.step, p.kind, p.device) for p in service.check(the_task, cell, k).problems] == problems
    jammed, working = service.batch([Configuration("jammed", ("jammed-robot", "gripper")),
                                     Configuration("working", ("robot", "gripper"))], list(k.devices), [the_task],
                                    workers=1, knowledge=k)
    assert working.plausible == ("pick-and-place",) and jammed.plausible == ()
    assert jammed.purchase is not None and jammed.purchase.impossible == (
        "step 1 of pick-and-place: device jammed-robot cannot play role robot from the state it is in; adding devices "
        "cannot cure it")


def test_a_role_no_catalogue_device_can_play_is_named_whichever_devices_the_configuration_holds() -> None:
    small = [d for d in service.catalogue() if d.id in ("robot", "sensor3d", "binpicking-pc")]
    for devices in (("robot",), ("binpicking-pc", "robot", "sensor3d")):
        (row,) = service.batch([Configuration("no-grippers", devices)], small, [task("pick-and-place")], workers=1)
        assert row.plausible == () and row.purchase is not None and row.purchase.options == ()
        assert (row.purchase.impossible or "").startswith(
            "step 1 of pick-and-place: no device can play role gripper, and no catalogue device can"), devices


def test_a_device_named_for_a_role_it_cannot_play_is_named_as_check_names_it(tmp_path: Path) -> None:
    the_task = service.task(write(tmp_path, "robot-grips.yaml", "task: robot-grips\nsteps:\n  - command: close-gripper\n"
                                  "    bind: {gripper: robot}\n    params: {grip_force: 30}\n"))
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    assert [(p.step, p.kind) for p in service.check(the_task, cell).problems] == [(1, "cannot_play")]
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 1 of robot-grips: device robot named for role gripper cannot play it; adding devices cannot cure it")
def test_a_finding_of_the_full_check_the_batch_has_no_words_for_is_named_by_its_kind(tmp_path: Path) -> None:
    linked = service.task(write(tmp_path, "hi.yaml", "task: hi\nsteps:\n  - name: localize\n    command: localize-part\n"
                                "  - command: pick\n    params:\n      pick_pose: {from: localize, output: part_pose}\n"
                                "      grip_force: 1000\n"))
    (row,) = service.batch([Configuration("paper", PAPER)], None, [linked], workers=1)
    assert row.to_json()["purchase"] == {"options": [], "impossible": "step 2 of hi: a finding of kind too_high (pnp "
                                                                      "check says why); adding devices cannot cure it"}


def test_a_device_the_task_names_that_no_catalogue_holds_cannot_be_bought(tmp_path: Path) -> None:
    own = service.task(write(tmp_path, "own.yaml", "task: own-gripper\nsteps:\n  - command: close-gripper\n"
                                                   "    bind: {gripper: my-gripper}\n"))
    (row,) = service.batch([Configuration("paper", PAPER)], None, [own], workers=1)
    assert row.to_json()["purchase"] == {"options": [], "impossible": "step 1 of own-gripper: device my-gripper named "
                                                                      "for role gripper is not in the cell; it is not "
                                                                      "in the catalogue"}


# ---- the batch binds each step's roles as check binds them

PICK_WITH_THE_GRIPPER = ("task: pick-with-the-gripper\nsteps:\n  - command: pick\n    bind: {gripper: gripper}\n"
                         "    params: {pick_pose: [0.35, 0.15, 0.04, 0, 180, 0], grip_force: 30}\n")
LOCALIZE_ANY = "task: localize\nsteps:\n  - command: localize-part\n    params: {exposure: 25, part_type: bracket}\n"


def _check_and_batch(tmp_path: Path, text: str, devices: tuple[str, ...]) -> tuple[CheckResult, BatchRow]:
    the_task = service.task(write(tmp_path, "task.yaml", text))
    cell = Cell("c", tuple(d for d in service.catalogue() if d.id in devices))
    (row,) = service.batch([Configuration("c", devices)], None, [the_task], workers=1)
    return service.check(the_task, cell), row


def test_a_role_left_to_the_configuration_after_a_named_one_is_bound_as_check_binds_it(tmp_path: Path) -> None:
    """The pick names its gripper (its first role: roles go in name order) and leaves its robot to the
    configuration: without a robot, or with two, the batch says what check says."""
    checked, row = _check_and_batch(tmp_path, PICK_WITH_THE_GRIPPER, ("gripper",))
    assert [(p.step, p.kind) for p in checked.problems] == [(1, "no_device")]
    assert row.plausible == () and row.purchase is not None and row.purchase.options[0][0] == ("scara",)
    checked, row = _check_and_batch(tmp_path, PICK_WITH_THE_GRIPPER, ("cobot", "gripper", "robot"))
    assert [(p.step, p.kind) for p in checked.problems] == [(1, "ambiguous")]
    assert row.plausible == () and row.purchase is not None and row.purchase.ambiguous == (
        "step 1 of pick-with-the-gripper: several devices can play role robot; bind step 1's role robot to one of "
        "them")
    checked, row = _check_and_batch(tmp_path, PICK_WITH_THE_GRIPPER, ("gripper", "robot"))
    assert checked.plausible and row.plausible == ("pick-with-the-gripper",) and row.purchase is None


def test_the_lone_player_of_a_role_is_bound_when_it_is_the_catalogues_first_device(tmp_path: Path) -> None:
    """The bin-picking PC comes first in the catalogue (its lowest bit): as the one localizer of the configuration
    it plays the role, as check says; it is not taken for several."""
    assert min(d.id for d in service.catalogue()) == "binpicking-pc"
    checked, row = _check_and_batch(tmp_path, LOCALIZE_ANY, ("binpicking-pc", "sensor3d"))
    assert checked.plausible and checked.steps[0].bindings == {"localizer": "binpicking-pc", "sensor": "sensor3d"}
    assert row.plausible == ("localize",) and row.purchase is None


def test_a_configuration_offers_the_processes_the_reasoner_says_it_offers() -> None:
    """Each configuration's offered processes are those ``pnp capabilities`` lists for it as a cell."""
    configs = [Configuration("gripper", ("gripper",)), Configuration("sensing", ("binpicking-pc", "sensor3d")),
               Configuration("arm", ("robot", "screwdriver")), Configuration("paper", PAPER),
               Configuration("no-gripper", ("binpicking-pc", "robot", "sensor3d"))]  # no bin-pick: it needs a gripper
    found = rows(configs)
    k = service.knowledge()
    assert [r.offered for r in found] == [o for o, _ in _reasoner(configs, tasks(), k)]
    assert found[0].offered == ("close-gripper", "open-gripper")
    f = engine(service.catalogue(), tasks(), k).feasibility  # asked without the roles filled: it finds them itself
    assert [f.offered(sum(f.abilities.bit(d) for d in c.devices)) for c in configs] == [
        r.offered for r in found]


# ---- a device that plays two roles of one step plays them in role order, the second from where the first left it

GRIP_AND_GO = """<?xml version="1.0" encoding="UTF-8"?>
<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:pnp="http://plugnproduce.org/ontology#"
       version="1.0" name="grip-and-go" initial="grip-and-go">
  <parallel id="grip-and-go">
    <state id="gripper" pnp:role="gripper" initial="gripper_open">
      <final id="gripper_open" pnp:concept="Open"/>
    </state>
    <state id="robot" pnp:role="robot" initial="robot_holding">
      <state id="robot_holding" pnp:concept="GripperState">
        <transition cond="In('gripper_open')" target="robot_moving"/>
      </state>
      <final id="robot_moving" pnp:concept="Moving"/>
    </state>
  </parallel>
</scxml>
"""
GRIP_AND_GO_TTL = """@prefix pnp:  <http://plugnproduce.org/ontology#> .
@prefix proc: <http://plugnproduce.org/processes/> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .

proc:grip-and-go a pnp:MotionProcess ;
    rdfs:label "grip and go" ;
    pnp:generalChart <grip-and-go.scxml> ;
    pnp:hasRole proc:grip-and-go-robot , proc:grip-and-go-gripper .

proc:grip-and-go-robot a pnp:Role ; pnp:roleName "robot" ; pnp:requiresSkill pnp:CanMove .
proc:grip-and-go-gripper a pnp:Role ; pnp:roleName "gripper" ; pnp:requiresSkill pnp:CanGrip .
"""


def _grip_arm(name: str, initial: str) -> tuple[str, str]:
    """A device that grips and moves: from ``open`` it goes nowhere, from ``ajar`` (also open) it closes, and only
    closed it moves."""
    ttl = (f"@prefix pnp: <http://plugnproduce.org/ontology#> .\n@prefix dev: <http://plugnproduce.org/devices/> .\n"
           f"dev:{name} a pnp:Robot ; pnp:hasSkill pnp:CanGrip , pnp:CanMove ; pnp:protocol pnp:XIRP ;\n"
           f"    pnp:endpoint \"xirp://127.0.0.1:0\" ; pnp:stateChart <{name}.scxml> ; pnp:commandTimeout 2.0 ;\n"
           f"    pnp:cost 5000 .\n")
    chart = f"""<?xml version="1.0" encoding="UTF-8"?>
<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:pnp="http://plugnproduce.org/ontology#"
       version="1.0" name="{name}" initial="{initial}">
  <state id="idle" pnp:concept="Idle">
    <transition event="xirp.request.Open" target="open"/>
  </state>
  <state id="open" pnp:concept="Open"/>
  <state id="ajar" pnp:concept="Open">
    <transition event="xirp.request.Close" target="closed"/>
  </state>
  <state id="closed" pnp:concept="Closed">
    <transition event="xirp.request.Move" target="moving"/>
  </state>
  <state id="moving" pnp:concept="Moving">
    <onentry><send event="motion.done" delay="100ms"/></onentry>
    <transition event="motion.done" target="at_pose"/>
  </state>
  <state id="at_pose" pnp:concept="AtPose">
    <transition event="xirp.request.Home" target="idle"/>
  </state>
</scxml>
"""
    return ttl, chart


def _grip_arms(library: Path) -> service.Knowledge:
    (library / "processes").mkdir(parents=True)
    (library / "processes" / "grip-and-go.scxml").write_text(GRIP_AND_GO, encoding="utf-8")
    (library / "processes" / "grip-and-go.ttl").write_text(GRIP_AND_GO_TTL, encoding="utf-8")
    (library / "devices").mkdir()
    for name, initial in (("idle-arm", "idle"), ("ajar-arm", "ajar")):
        ttl, chart = _grip_arm(name, initial)
        (library / "devices" / f"{name}.ttl").write_text(ttl, encoding="utf-8")
        (library / "devices" / f"{name}.scxml").write_text(chart, encoding="utf-8")
    return service.knowledge((library,))


def _both_roles(tmp_path: Path, device: str) -> tuple[CheckResult, BatchRow]:
    k = _grip_arms(tmp_path / "library")
    the_task = service.task(write(tmp_path, "task.yaml", "task: grip-and-go\nsteps:\n  - command: grip-and-go\n"
                                                         f"    bind: {{gripper: {device}, robot: {device}}}\n"))
    cell = Cell("c", tuple(d for d in k.devices if d.id == device))
    (row,) = service.batch([Configuration("c", (device,))], [d for d in k.devices if d.id == device], [the_task],
                           workers=1, knowledge=k)
    return service.check(the_task, cell, k), row


def test_a_device_whose_first_role_starts_wrong_plays_its_second_from_where_the_first_recovers(tmp_path: Path) -> None:
    """The idle arm is not open for the gripper role (its first, in name order), which leaves it where the role ends
    from an open state (``open``); from there the robot role has no way on. Check names the stuck robot role first;
    so does the batch, and no purchase cures it."""
    checked, row = _both_roles(tmp_path, "idle-arm")
    assert [(p.step, p.kind, p.role) for p in checked.problems] == [(1, "stuck", "robot"), (1, "wrong_state", "gripper")]
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 1 of grip-and-go: device idle-arm cannot play role robot from the state it is in; adding devices "
        "cannot cure it")


def test_a_device_plays_its_second_role_from_where_its_first_left_it(tmp_path: Path) -> None:
    """The ajar arm plays the gripper role where it is (``ajar``, not the other open state), and from there the robot
    role closes and moves it: plausible in check and in the batch."""
    checked, row = _both_roles(tmp_path, "ajar-arm")
    assert checked.plausible and checked.problems == ()
    assert row.plausible == ("grip-and-go",) and row.purchase is None


# ---- an odd cycle of roles: three roles, each playable by two of three devices, and no set fills each once

TRIO = """<?xml version="1.0" encoding="UTF-8"?>
<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:pnp="http://plugnproduce.org/ontology#"
       version="1.0" name="trio" initial="trio">
  <parallel id="trio">
    <state id="grip" pnp:role="grip" initial="grip_any"><final id="grip_any" pnp:concept="StateConcept"/></state>
    <state id="move" pnp:role="move" initial="move_any"><final id="move_any" pnp:concept="StateConcept"/></state>
    <state id="sense" pnp:role="sense" initial="sense_any"><final id="sense_any" pnp:concept="StateConcept"/></state>
  </parallel>
</scxml>
"""
TRIO_TTL = """@prefix pnp:  <http://plugnproduce.org/ontology#> .
@prefix proc: <http://plugnproduce.org/processes/> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .

proc:trio a pnp:MotionProcess ;
    rdfs:label "trio" ;
    pnp:generalChart <trio.scxml> ;
    pnp:hasRole proc:trio-grip , proc:trio-move , proc:trio-sense .

proc:trio-grip a pnp:Role ; pnp:roleName "grip" ; pnp:requiresSkill pnp:CanGrip .
proc:trio-move a pnp:Role ; pnp:roleName "move" ; pnp:requiresSkill pnp:CanMove .
proc:trio-sense a pnp:Role ; pnp:roleName "sense" ; pnp:requiresSkill pnp:CanSense3D .
"""
STATES = {"CanGrip": (("open", "Open"), ("closed", "Closed")), "CanMove": (("idle", "Idle"), ("at_pose", "AtPose")),
          "CanSense3D": (("ready", "SensorReady"), ("captured", "Captured"))}


def _two_skills(library: Path, name: str, skills: tuple[str, str], cost: int) -> None:
    """A device of two skills whose chart goes round the states each skill needs, by a request each."""
    states = [s for skill in skills for s in STATES[skill]]
    body = "".join(f'  <state id="{x}" pnp:concept="{c}">\n    <transition event="xirp.request.Next" '
                   f'target="{states[(n + 1) % len(states)][0]}"/>\n  </state>\n' for n, (x, c) in enumerate(states))
    (library / "devices" / f"{name}.scxml").write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<scxml xmlns="http://www.w3.org/2005/07/scxml" '
        f'xmlns:pnp="http://plugnproduce.org/ontology#"\n       version="1.0" name="{name}" initial="{states[0][0]}">\n'
        f"{body}</scxml>\n", encoding="utf-8")
    (library / "devices" / f"{name}.ttl").write_text(
        f"@prefix pnp: <http://plugnproduce.org/ontology#> .\n@prefix dev: <http://plugnproduce.org/devices/> .\n"
        f"dev:{name} a pnp:Robot ; pnp:hasSkill pnp:{skills[0]} , pnp:{skills[1]} ; pnp:protocol pnp:XIRP ;\n"
        f'    pnp:endpoint "xirp://127.0.0.1:0" ; pnp:stateChart <{name}.scxml> ; pnp:commandTimeout 2.0 ;\n'
        f"    pnp:cost {cost} .\n", encoding="utf-8")


def test_an_odd_cycle_of_roles_has_no_purchase_and_the_search_says_so_when_it_runs_out(tmp_path: Path) -> None:
    """Each pair of the three devices shares a role, so every set fills some role twice or leaves one empty: check
    finds every set of them wanting, and the batch, having looked at each, says that no set makes the task
    plausible (with no example: no set fills each role once)."""
    library = tmp_path / "library"
    (library / "processes").mkdir(parents=True)
    (library / "processes" / "trio.scxml").write_text(TRIO, encoding="utf-8")
    (library / "processes" / "trio.ttl").write_text(TRIO_TTL, encoding="utf-8")
    (library / "devices").mkdir()
    for name, skills, price in (("grip-move", ("CanGrip", "CanMove"), 100), ("move-sense", ("CanMove", "CanSense3D"),
                                                                              200),
                                ("sense-grip", ("CanSense3D", "CanGrip"), 300)):
        _two_skills(library, name, skills, price)
    k = service.knowledge((library,))
    own = [d for d in k.devices if d.id in ("grip-move", "move-sense", "sense-grip")]
    the_task = service.task(write(tmp_path, "trio.yaml", "task: trio\nsteps:\n  - command: trio\n"))
    for size in range(4):
        for chosen in itertools.combinations(own, size):
            assert not service.check(the_task, Cell("c", chosen), k).plausible, chosen
    (row,) = service.batch([Configuration("empty", ())], own, [the_task], workers=1, knowledge=k)
    assert row.outcome == "impossible" and row.purchase is not None
    assert row.purchase.impossible == "no set of catalogue devices makes every task plausible"
    (row,) = service.batch([Configuration("one", ("grip-move",))], own, [the_task], workers=1, knowledge=k)
    assert row.purchase is not None and row.purchase.impossible == (  # the search fills the sense role only
        "no set of catalogue devices makes every task plausible; e.g. adding move-sense: step 1 of trio: several "
        "devices can play role move")


# ---- answers are remembered by what they depend on, and only by that

def _together_and_alone(the_task: Task, configs: list[Configuration]) -> tuple[list[BatchRow], list[BatchRow]]:
    together = list(service.batch(configs, None, [the_task], workers=1))
    alone = [row for c in configs for row in service.batch([c], None, [the_task], workers=1)]
    return together, alone


def test_a_configuration_is_answered_in_a_batch_as_alone_whether_the_device_a_task_names_is_there(
        tmp_path: Path) -> None:
    """The task names the robot for the gripper role: with the robot, it cannot play it; without, it is absent."""
    the_task = service.task(write(tmp_path, "robot-grips.yaml", "task: robot-grips\nsteps:\n  - command: close-gripper\n"
                                  "    bind: {gripper: robot}\n    params: {grip_force: 30}\n"))
    together, alone = _together_and_alone(the_task, [Configuration("with", ("gripper", "robot")),
                                                     Configuration("without", ("gripper",))])
    assert together == alone
    assert [r.purchase.impossible if r.purchase else None for r in together] == [
        "step 1 of robot-grips: device robot named for role gripper cannot play it; adding devices cannot cure it",
        "no set of catalogue devices makes every task plausible; e.g. adding robot: step 1 of robot-grips: device "
        "robot named for role gripper cannot play it"]


def test_a_lone_first_device_and_several_players_of_a_role_are_answered_apart_in_one_batch(tmp_path: Path) -> None:
    """The bin-picking PC alone localizes; beside the UPnP one the role is ambiguous, in one batch as alone."""
    together, alone = _together_and_alone(service.task(write(tmp_path, "localize.yaml", LOCALIZE_ANY)),
                                          [Configuration("lone", ("binpicking-pc", "sensor3d")),
                                           Configuration("two", ("binpicking-pc", "binpicking-pc-ua", "sensor3d"))])
    assert together == alone
    assert together[0].plausible == ("localize",) and together[1].plausible == ()
    assert together[1].purchase is not None and (together[1].purchase.ambiguous or "").startswith(
        "step 1 of localize: several devices can play role localizer")


def test_a_step_whose_command_names_no_process_is_named_as_check_names_it(tmp_path: Path) -> None:
    the_task = service.task(write(tmp_path, "wave.yaml", "task: wave\nsteps:\n  - command: wave-hello\n"
                                  "  - command: close-gripper\n    params: {grip_force: 30}\n"))
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    assert [(p.step, p.kind) for p in service.check(the_task, cell).problems] == [(1, "unknown_command")]
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 1 of wave: no process has this name; adding devices cannot cure it")


def test_a_value_outside_the_process_range_is_named_as_not_fitting_its_declaration(tmp_path: Path) -> None:
    fast = service.task(write(tmp_path, "fast.yaml", WITHIN_EVERY_ROBOT.replace("grip_force: 30", "grip_force: 30\n"
                                                                                 "      speed: 101")))
    (row,) = service.batch([Configuration("paper", PAPER)], None, [fast], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 1 of pick-and-place: a parameter value does not fit its declaration; adding devices cannot cure it")


def test_a_role_the_process_does_not_have_is_named_as_check_names_it(tmp_path: Path) -> None:
    the_task = service.task(write(tmp_path, "hand.yaml", "task: hand\nsteps:\n  - command: close-gripper\n"
                                  "    bind: {hand: gripper}\n    params: {grip_force: 30}\n"))
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    assert [(p.step, p.kind) for p in service.check(the_task, cell).problems] == [(1, "unknown_role")]
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 1 of hand: the process has no role hand; adding devices cannot cure it")



@pytest.mark.parametrize("last", ["  - command: wave-hello\n",
                                  "  - command: open-gripper\n    bind: {hand: gripper}\n"], ids=["command", "role"])
def test_the_states_are_followed_past_an_unknown_command_or_role_as_check_follows_them(tmp_path: Path,
                                                                                        last: str) -> None:
    """Close, close, then a step check cannot bind as written: check names the second close first (the gripper is
    closed already), and the batch names it too, not the later step."""
    the_task = service.task(write(tmp_path, "task.yaml", CLOSE_TWICE + last))
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    assert [p.step for p in service.check(the_task, cell).problems][:2] == [2, 3]
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 2 of close-twice: device gripper is not in the state role gripper starts from; adding devices cannot "
        "cure it")


def test_the_states_are_followed_once_a_purchase_fills_every_role(tmp_path: Path) -> None:
    """No robot for the first step's move: the batch looks for one to buy before it follows the gripper's states,
    and then finds that the second close finds the gripper closed, which no purchase cures."""
    text = ("task: move-then-close-twice\nsteps:\n  - command: move-to\n    params: {target_pose: [0.30, 0.00, 0.40, 0, "
            "180, 0], speed: 50}\n" + CLOSE_TWICE.split("steps:\n", 1)[1])
    the_task = service.task(write(tmp_path, "task.yaml", text))
    cell = Cell("gripper-only", tuple(d for d in service.catalogue() if d.id == "gripper"))
    assert [(p.step, p.kind) for p in service.check(the_task, cell).problems] == [(1, "no_device"), (3, "wrong_state")]
    (row,) = service.batch([Configuration("gripper-only", ("gripper",))], None, [the_task], workers=1)
    assert row.purchase is not None and row.purchase.impossible == (
        "no set of catalogue devices makes every task plausible; e.g. adding scara: step 3 of move-then-close-twice: "
        "device gripper is not in the state role gripper starts from")


def test_findings_are_named_in_step_order(tmp_path: Path) -> None:
    """The move's pose is beyond the robot's reach (step 1, role robot) and the close's force beyond its process's
    range (step 2, no role): the first named is the first step's, as check names it first."""
    text = ("task: far-then-hard\nsteps:\n  - command: move-to\n    params: {target_pose: [1.48, 0.00, 0.40, 0, 180, 0], "
            "speed: 50}\n  - command: close-gripper\n    params: {grip_force: 150}\n")
    the_task = service.task(write(tmp_path, "task.yaml", text))
    cell = Cell("paper", tuple(d for d in service.catalogue() if d.id in PAPER))
    assert [(p.step, p.kind) for p in service.check(the_task, cell).problems] == [(1, "device_limit"), (2, "too_high")]
    (row,) = service.batch([Configuration("paper", PAPER)], None, [the_task], workers=1)
    assert row.purchase is not None and (row.purchase.impossible or "").startswith(
        "step 1 of far-then-hard: device robot (role robot) refuses a value sent to it by its own limits")


def test_a_value_no_command_of_the_bound_device_accepts_is_named_as_check_names_it(
        tmp_path: Path, vacuum_with_default: DeviceDescription) -> None:
    """The vacuum gripper (with a default vacuum, so that it can close) has no command that takes a grip force."""
    the_task = service.task(write(tmp_path, "t.yaml", "task: t\nsteps:\n  - command: close-gripper\n"
                                  "    params: {grip_force: 50}\n"))
    catalogue = [d for d in service.catalogue() if d.id != "vacuum-gripper"] + [vacuum_with_default]
    cell = Cell("vacuum", tuple(d for d in catalogue if d.id in ("robot", "vacuum-gripper")))
    assert [(p.step, p.kind) for p in service.check(the_task, cell).problems] == [(1, "not_accepted")]
    (row,) = service.batch([Configuration("vacuum", ("robot", "vacuum-gripper"))], catalogue, [the_task], workers=1)
    assert row.plausible == () and row.purchase is not None and row.purchase.impossible == (
        "step 1 of t: device vacuum-gripper (role gripper) accepts no command for a parameter value given; adding "
        "devices cannot cure it")
