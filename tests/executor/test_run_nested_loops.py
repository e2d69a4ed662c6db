"""``pnp run bin-picking-in-rounds.yaml --sim``: rounds of at most three picks, each ended by a move home."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from tests.executor.test_run_until_empty import journal_of, pnp

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
    result = pnp("run", str(TASK), "--sim", "--bin-parts", str(parts), "--bin-seed", str(seed),
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    assert rounds_of(journal) == expected
    records = journal_of(journal)
    found = [r["params"]["outcome"] for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert found.count("PartFound") == parts
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "succeeded"
