"""The answer ``pnp verify`` prints, line by line and as JSON: the verdict with its counts, the problem and the
numbered shortest counterexample, each step at its description line."""

from __future__ import annotations

from plugnproduce.verification.results import INCONCLUSIVE, PROVED, REFUTED, TraceStep, Verification

TRACE = [TraceStep("controller starts the task; sends xirp.request.Scan to sensor3d", "tasks/bin-picking.yaml:3"),
         TraceStep("gripper receives xirp.request.Close in state standby, which has no transition for it",
                   "devices/gripper.scxml:41")]
REFUSED = "device gripper in state standby refuses xirp.request.Close: its chart has no transition for it there"


def test_a_refuted_task_reads_its_counts_its_problem_and_each_step_of_the_counterexample_at_its_line() -> None:
    answer = Verification("bin-picking", "bin-picking", REFUTED, 120, 341, 1.23456, REFUSED, TRACE)
    assert answer.lines() == [
        "task bin-picking on cell bin-picking: refuted (120 states, 341 transitions, 1.23 s)",
        REFUSED,
        "shortest counterexample (2 steps):",
        "  1. tasks/bin-picking.yaml:3: controller starts the task; sends xirp.request.Scan to sensor3d",
        "  2. devices/gripper.scxml:41: gripper receives xirp.request.Close in state standby, "
        "which has no transition for it"]
    assert not answer.proved


def test_a_proved_task_is_one_line() -> None:
    answer = Verification("glue", "glue-cell", PROVED, 5, 4, 0.5)
    assert answer.lines() == ["task glue on cell glue-cell: proved (5 states, 4 transitions, 0.50 s); "
                              "every interleaving reaches done"]
    assert answer.proved


def test_an_inconclusive_task_says_which_budget_ran_out_and_shows_no_counterexample() -> None:
    ran_out = "the budget of 10 states ran out before every interleaving was explored"
    answer = Verification("glue", "glue-cell", INCONCLUSIVE, 10, 12, 0.012, ran_out)
    assert answer.lines() == ["task glue on cell glue-cell: inconclusive (10 states, 12 transitions, 0.01 s)", ran_out]
    assert not answer.proved


def test_the_json_answer_has_every_field_and_the_seconds_to_the_millisecond() -> None:
    answer = Verification("bin-picking", "bin-picking", REFUTED, 120, 341, 1.23456, REFUSED, TRACE)
    assert answer.to_json() == {
        "task": "bin-picking", "cell": "bin-picking", "verdict": "refuted", "states": 120, "transitions": 341,
        "seconds": 1.235, "problem": REFUSED,
        "trace": [{"where": "tasks/bin-picking.yaml:3",
                   "step": "controller starts the task; sends xirp.request.Scan to sensor3d"},
                  {"where": "devices/gripper.scxml:41",
                   "step": "gripper receives xirp.request.Close in state standby, which has no transition for it"}]}
