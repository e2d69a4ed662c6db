"""The run view shows which branch each step with branches took, as the journal recorded it."""

from __future__ import annotations

from plugnproduce.hmi.views import run_json

RECORDS = [
    {"kind": "start", "task": "bin-picking-then-home", "cell": "bin-picking", "steps": 8, "states": {}, "seq": 1},
    {"kind": "step", "step": 1, "command": "localize-part", "seq": 2},
    {"kind": "branch", "step": 1, "outcome": "BinEmpty", "branch": "NoPartFound",
     "path": "branch NoPartFound at step 1", "next": 4, "seq": 3},
    {"kind": "step", "step": 4, "command": "move-to", "seq": 4},
    {"kind": "end", "outcome": "succeeded", "seq": 5},
]


def test_the_run_view_lists_the_branches_taken_and_says_so_in_its_lines() -> None:
    view = run_json("r1", RECORDS, active=False)
    assert [(b["step"], b["outcome"], b["branch"]) for b in view["branches"]] == [(1, "BinEmpty", "NoPartFound")]
    assert "  step 1 reported BinEmpty: the task takes branch NoPartFound at step 1" in view["lines"]
    assert view["status"] == "succeeded"
