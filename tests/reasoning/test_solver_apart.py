"""A large program is ground and solved in a thread of its own (:data:`solver.APART`): the caller gets the same
model as from a small program, and clingo's refusal as the same one-line :class:`EncodingError`."""

from __future__ import annotations

import threading

import pytest

from plugnproduce.errors import EncodingError
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from tests.reasoning.test_encodings import WORLD, cell


def padded(facts: str, tag: str) -> str:
    """The same program, made large by a comment (and distinct per test, so no cached answer is read)."""
    return facts + f"\n% {tag} " + "x" * solver.APART + "\n"


def offered(facts: str) -> set[tuple[str, str, str]]:
    return {(a.p, a.r, a.d) for a in solver.solve(solver.CAPABILITIES, facts)[s.CanPlay]}


def test_a_large_program_answers_as_a_small_one_from_a_thread_of_its_own(monkeypatch: pytest.MonkeyPatch) -> None:
    facts = WORLD + cell("g", "r")
    threads: list[str] = []
    start = threading.Thread.start

    def counted(self: threading.Thread) -> None:
        threads.append(self.name)
        start(self)

    monkeypatch.setattr(threading.Thread, "start", counted)
    small = offered(facts)
    assert threads == []
    large = offered(padded(facts, "same answer"))
    assert threads == ["pnp-solve"]
    assert large == small
    assert ("pick", "gripper", "g") in large and ("move", "robot", "r") in large


def test_a_large_program_clingo_refuses_is_one_encoding_error_in_the_callers_thread() -> None:
    with pytest.raises(EncodingError, match="clingo could not ground"):
        solver.solve(solver.CAPABILITIES, padded(WORLD + cell("g", "r") + "device(", "refused"))
