"""``pnp run bin-picking-in-rounds.yaml --sim``: rounds of at most three picks, each ended by a move home."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from tests.executor.test_run_until_empty import SPEED, journal_of, pnp

TASK = service.builtin("tasks", "bin-picking-in-rounds.yaml")
ROUND_1 = [1, 4, 4]
"""The step positions of localize in the first round: the inner loop's first iteration, then its later ones."""
LATER = [8, 11, 11]
"""The same in the rounds after it (the outer loop's later iterations' copy of the body)."""


def rounds_of(journal: Path) -> list[list[int]]:
    """The localize steps each round ran (by position), split at the move home that ends the round."""
    out: list[list[int]] = [[]]
    for r in journal_of(journal):
        if r["kind"] == "step" and r["command"] == "localize-part":
            out[-1].append(r["step"])
        elif r["kind"] == "step" and r["command"] == "move-to":
            out.append([])
    return out


@pytest.mark.parametrize(("parts", "seed", "expected"), [
    (9, 2, [ROUND_1, LATER, LATER, []]),  # each round restarts the inner loop: three picks in the third one too
    (7, 3, [ROUND_1, LATER, [8, 11], []]),  # the bin empties in round 3: BinEmpty ends the round, not the task
    (0, 1, [[1], [8], [8], []]),
])
def test_each_round_picks_up_to_three_parts_and_goes_home(tmp_path: Path, parts: int, seed: int,
                                                          expected: list[list[int]]) -> None:
    journal = tmp_path / "run.jsonl"
    result = pnp("run", str(TASK), "--sim", "--bin-parts", str(parts), "--bin-seed", str(seed), "--speed", SPEED,
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert rounds_of(journal) == expected
    records = journal_of(journal)
    found = [r["params"]["outcome"] for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert found.count("PartFound") == parts
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "succeeded"


NESTED = """task: nested-{outer}x{inner}
steps:
  - loop:
      max: {outer}
      steps:
        - loop:
            max: {inner}
            steps:
              - command: move-to
                params:
                  target_pose: [0.30, 0.00, 0.40, 0, 180, 0]
"""
"""An outer loop whose body is an inner loop only: the inner loop's last step ends the outer body too."""


@pytest.mark.parametrize(("outer", "inner"), [(2, 2), (3, 3), (2, 3)])
def test_a_loop_whose_body_ends_with_an_inner_loop_runs_every_iteration_of_both(tmp_path: Path, outer: int,
                                                                                 inner: int) -> None:
    """After the inner loop's last step the inner loop decides first: it goes on until its max, and only then
    does the outer loop count an iteration (deciding the other way round ends an inner loop one step early)."""
    task, journal = tmp_path / "nested.yaml", tmp_path / "run.jsonl"
    task.write_text(NESTED.format(outer=outer, inner=inner), encoding="utf-8")
    result = pnp("run", str(task), "--sim", "--speed", SPEED, "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    records = journal_of(journal)
    steps = [r["step"] for r in records if r["kind"] == "step"]
    assert len(steps) == outer * inner
    assert steps == [1] + [2] * (inner - 1) + ([3] + [4] * (inner - 1)) * (outer - 1)  # first iterations, then copies
    moves = [r for r in records if r["kind"] == "command" and r["device"] == "robot" and r["command"] == "MoveTo"]
    assert len(moves) == outer * inner
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "succeeded"
