"""Encodings are parsed once a process and added to each ``Control`` as parsed statements: the same answers as
their text, and an encoding read again with other text is parsed again, never served from the old parse."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from plugnproduce.errors import EncodingError
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from plugnproduce.resources import rules_path
from tests.reasoning.test_encodings import WORLD, cell


@pytest.fixture
def rules(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A copy of the encodings that a test may edit, read in place of the package's."""
    for f in rules_path().glob("*.lp"):
        shutil.copy(f, tmp_path / f.name)
    monkeypatch.setattr(solver, "rules_path", lambda: tmp_path)
    solver.encoding.cache_clear()
    yield tmp_path
    solver.encoding.cache_clear()  # the next test reads the package's own again


def offered(facts: str) -> set[tuple[str, str, str]]:
    return {(a.p, a.r, a.d) for a in solver.solve(solver.CAPABILITIES, facts)[s.CanPlay]}


def test_an_edited_encoding_read_again_gives_the_edited_answer(rules: Path) -> None:
    facts = WORLD + cell("g", "r")
    before = offered(facts)
    assert ("pick", "gripper", "g") in before
    roles = rules / "roles.lp"
    roles.write_text(roles.read_text(encoding="utf-8") + '\ncan_play("weld","torch","g").\n', encoding="utf-8")
    solver.encoding.cache_clear()
    after = offered(facts + "% read again\n")
    assert after == before | {("weld", "torch", "g")}


def test_an_encoding_clingo_cannot_parse_is_one_encoding_error(rules: Path) -> None:
    (rules / "offered.lp").write_text("offered(P :- process(P).\n", encoding="utf-8")
    with pytest.raises(EncodingError, match=r"clingo could not ground .*offered\.lp.*syntax error"):
        offered(WORLD + cell("g", "r") + "% refused\n")
