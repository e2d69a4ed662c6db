"""pnp validate on tasks with branches and loops: each outcome that cannot work is a finding at its line."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.validation import validate_paths
from plugnproduce.validation.findings import Report

TASK = """task: findings
steps:
  - command: localize-part
    on:
      NoPartFund:
        - command: scan-bin
      PartFound:
        - command: scan-bin
          on:
            BinEmpty: [{command: scan-bin}]
  - command: localize-part
    on:
      NoPartFound: [{command: scan-bin}]
      BinEmpty: [{command: scan-bin}]
  - loop:
      until: BinEmpty
      max: 3
      steps:
        - command: localize-part
          on:
            BinEmpty: [{command: scan-bin}]
  - loop:
      until: BinEmty
      max: 3
      steps:
        - command: localize-part
  - loop:
      while: PartFound
      steps:
        - command: move-to
"""


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Report]:
    path = tmp_path_factory.mktemp("tasks") / "findings.yaml"
    path.write_text(TASK, encoding="utf-8")
    return path, validate_paths([path])


@pytest.mark.parametrize(
    ("line", "message"),
    [
        (5, "step 1 (localize-part): branch NoPartFund: NoPartFund is not an outcome of the ontology; "
            "did you mean NoPartFound or PartFound?"),
        (10, "step 3 (scan-bin): branch BinEmpty is unreachable: scan-bin reports no outcome"),
        (13, "step 5 (localize-part): branch NoPartFound is unreachable: localize-part ends with PartFound, "
             "BinEmpty only, and each of those that falls under it has a branch of its own"),
        (21, "step 8 (localize-part): branch BinEmpty is unreachable: the outcome that would take it (BinEmpty) "
             "ends the loop first (until BinEmpty)"),
        (23, "loop until BinEmty: BinEmty is not an outcome of the ontology; did you mean BinEmpty?"),
        (28, "loop while PartFound: no step of its body can end with that outcome, so the loop never goes on "
             "after iteration 1; its steps' outcomes: none"),
    ],
)
def test_each_outcome_that_cannot_work_is_a_finding_at_its_line(report: tuple[Path, Report], line: int,
                                                                 message: str) -> None:
    path, found = report
    assert (str(path), line, message) in [(p.file, p.line, p.message) for p in found.problems]


def test_a_well_formed_branch_is_no_finding(report: tuple[Path, Report]) -> None:
    path, found = report
    assert not [p for p in found.problems if p.line in (7, 14)], [str(p) for p in found.problems]


def test_a_loop_that_goes_on_on_every_outcome_has_no_exit(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_text("task: t\nsteps:\n  - loop:\n      while: Outcome\n      steps:\n"
                    "        - command: localize-part\n", encoding="utf-8")
    messages = [(p.line, p.message) for p in validate_paths([path]).problems]
    assert (4, "loop while Outcome has no exit: every outcome its steps can end with (BinEmpty, PartFound) lets "
               "it go on, and it has no max") in messages


NESTED = """task: t
steps:
  - loop:
      until: BinEmpty
      max: 3
      steps:
        - loop:
            until: BinEmpty
            max: 3
            steps:
              - command: localize-part
        - command: scan-bin
"""
INNER_ENDS_FIRST = ("loop until BinEmpty: every step of its body that can end with that outcome lies in an inner loop "
                    "that ends on it first, so the loop never ends on it")


@pytest.mark.parametrize(("text", "found"), [
    (NESTED, [(4, INNER_ENDS_FIRST)]),
    # the outer loop's own first step can end it, at the start of the task or after another step
    (NESTED.replace("        - loop:\n", "        - command: localize-part\n        - loop:\n", 1), []),
    (NESTED.replace("steps:\n  - loop:", "steps:\n  - command: scan-bin\n  - loop:", 1)
     .replace("        - loop:\n", "        - command: localize-part\n        - loop:\n", 1), []),
], ids=["only-inner", "own-first-step", "own-first-step-after-another"])
def test_an_outcome_only_an_inner_loop_ends_on_never_ends_the_outer_loop(tmp_path: Path, text: str,
                                                                          found: list[tuple[int, str]]) -> None:
    path = tmp_path / "t.yaml"
    path.write_text(text, encoding="utf-8")
    assert [(p.line, p.message) for p in validate_paths([path]).problems if p.message.startswith("loop")] == found


def test_a_finding_inside_a_loop_is_reported_once_not_again_for_its_later_iterations(
        report: tuple[Path, Report]) -> None:
    path, found = report
    assert [p.line for p in found.problems].count(21) == 1


def test_a_step_after_the_loop_is_not_part_of_its_body(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_text("task: t\nsteps:\n  - loop:\n      until: BinEmpty\n      max: 3\n      steps:\n"
                    "        - command: scan-bin\n  - command: localize-part\n", encoding="utf-8")
    assert [(p.line, p.message) for p in validate_paths([path]).problems] == [
        (4, "loop until BinEmpty: no step of its body can end with that outcome, so the loop never ends on it; "
            "its steps' outcomes: none")]


def test_a_branch_on_an_outcome_the_loop_does_not_end_on_is_no_finding(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_text("task: t\nsteps:\n  - loop:\n      until: BinEmpty\n      max: 3\n      steps:\n"
                    "        - command: localize-part\n          on:\n            PartFound: [{command: scan-bin}]\n",
                    encoding="utf-8")
    assert [(p.line, p.message) for p in validate_paths([path]).problems] == []
