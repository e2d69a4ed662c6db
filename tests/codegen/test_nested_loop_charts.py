"""Generated charts for a loop inside a loop: W3C-valid, not unrolled, inner counters restarted."""

from __future__ import annotations

from plugnproduce import service
from plugnproduce.codegen import generate_task
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.description.loader import parse_task
from plugnproduce.description.model import Cell, ProcessDescription
from plugnproduce.resources import descriptions_path
from plugnproduce.statechart import parse_chart, schema_problems
from plugnproduce.statechart.model import Assign, Transition, walk
from tests.codegen.conftest import bind_by_skill
from tests.codegen.test_loops_and_links import rule_taken, run, size
from tests.executor.test_run_nested_loops import NESTED

ROUNDS = (descriptions_path() / "tasks" / "bin-picking-in-rounds.yaml").read_text(encoding="utf-8")


def generated(text: str, cell: Cell, processes: dict[str, ProcessDescription]) -> tuple[bytes, bytes]:
    task = parse_task(text.encode(), "task.yaml")
    out = generate_task(task, cell, bind_by_skill(task, cell, processes), processes, service.knowledge().taxonomy)
    return out.task_chart(), closed_world_chart(out, cell)


def test_the_nested_chart_is_w3c_valid(bin_picking_cell, processes) -> None:
    chart, closed = generated(ROUNDS, bin_picking_cell, processes)
    assert schema_problems(chart, "task.scxml") == []
    assert schema_problems(closed, "closed.scxml") == []


def test_the_chart_does_not_grow_with_either_maximum(bin_picking_cell, processes) -> None:
    few, _ = generated(ROUNDS, bin_picking_cell, processes)
    many, _ = generated(ROUNDS.replace("max: 3", "max: 50000"), bin_picking_cell, processes)
    assert size(few) == size(many)


def test_each_copy_of_the_inner_loop_counts_its_own_iterations(bin_picking_cell, processes) -> None:
    chart, _ = generated(ROUNDS, bin_picking_cell, processes)
    counters = {a.location for a in walk(parse_chart(chart, "task.scxml"))
                if isinstance(a, Assign) and a.location.startswith("pnp_rounds_")}
    assert counters == {"pnp_rounds_1", "pnp_rounds_2", "pnp_rounds_3"}


def test_another_outer_iteration_restarts_the_inner_loop_of_its_body(bin_picking_cell, processes) -> None:
    chart, _ = generated(ROUNDS, bin_picking_cell, processes)
    again = [t for t in walk(parse_chart(chart, "task.scxml"))
             if isinstance(t, Transition) and "pnp_rounds_1 + 1 < 3" in (t.cond or "")]
    assert [[(a.location, a.expr) for a in t.actions if isinstance(a, Assign)] for t in again] == [
        [("pnp_rounds_1", "pnp_rounds_1 + 1"), ("pnp_step", "7"), ("pnp_rounds_3", "0")]]


def test_the_closed_world_runs_the_nested_loops_to_done(bin_picking_cell, processes) -> None:
    _, closed = generated(ROUNDS, bin_picking_cell, processes)
    assert run(closed) == {"done"}


def test_where_an_inner_loop_ends_the_outer_body_the_inner_loop_decides_first(bin_picking_cell, processes) -> None:
    # outer loop 1 (positions 1-4), its body only an inner loop: loop 2 in the first copy (1-2), loop 3 in the later
    # one (3-4); both loops end at position 4 (pnp_step counts the steps done: a loop goes on from its later copy)
    chart, _ = generated(NESTED.format(outer=3, inner=3), bin_picking_cell, processes)
    in_both = {"pnp_step": 4, "pnp_rounds_1": 1, "pnp_rounds_2": -1, "pnp_outcome": None}
    assert rule_taken(chart, {**in_both, "pnp_rounds_3": 1}) == [("pnp_rounds_3", "pnp_rounds_3 + 1"),
                                                                 ("pnp_step", "3")]
    assert rule_taken(chart, {**in_both, "pnp_rounds_3": 2}) == [("pnp_rounds_3", "-1")]
    assert rule_taken(chart, {**in_both, "pnp_rounds_3": -1}) == [("pnp_rounds_1", "pnp_rounds_1 + 1"),
                                                                  ("pnp_step", "2"), ("pnp_rounds_3", "0")]


WHILE_IN_WHILE = """task: look-again
steps:
  - loop:
      while: NoPartFound
      max: 3
      steps:
        - loop:
            while: NoPartFound
            max: 3
            steps:
              - command: localize-part
"""
"""Look again while no part is found, in rounds: loop 1 the rounds (1-4), loop 2 the looking in the first round
(1-2), loop 3 in the later ones (3-4)."""


def test_an_inner_while_loop_leaves_the_outcome_to_the_outer_loop_which_then_resets_it(
        bin_picking_cell, processes) -> None:
    chart, _ = generated(WHILE_IN_WHILE, bin_picking_cell, processes)
    found = {"pnp_rounds_1": 1, "pnp_rounds_2": -1, "pnp_outcome": "PartFound"}
    # the inner loops stop on a found part, at the end of their first iteration or a later one, keeping the outcome
    assert rule_taken(chart, {**found, "pnp_step": 1, "pnp_rounds_2": 0}) == [("pnp_step", "2"), ("pnp_rounds_2", "-1")]
    assert rule_taken(chart, {**found, "pnp_step": 4, "pnp_rounds_3": 1}) == [("pnp_rounds_3", "-1")]
    # then the outer loop stops on it too, and only it forgets the outcome
    assert rule_taken(chart, {**found, "pnp_step": 4, "pnp_rounds_3": -1}) == [("pnp_outcome", "None"),
                                                                               ("pnp_rounds_1", "-1")]


def test_a_while_loop_stops_after_its_first_iteration_and_forgets_the_outcome(bin_picking_cell, processes) -> None:
    chart, _ = generated(WHILE_IN_WHILE.replace("        - loop:\n            while: NoPartFound\n            max: 3\n"
                                                "            steps:\n              - command: localize-part\n",
                                                "        - command: localize-part\n"), bin_picking_cell, processes)
    assert rule_taken(chart, {"pnp_step": 1, "pnp_rounds_1": 0, "pnp_outcome": "PartFound"}) == [
        ("pnp_step", "2"), ("pnp_outcome", "None"), ("pnp_rounds_1", "-1")]
