"""The ASP mutator of ``scripts/mutation_asp.py``: the changes it makes to an encoding, and where it says they are."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from plugnproduce.resources import rules_path

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def asp():
    spec = importlib.util.spec_from_file_location("mutation_asp", ROOT / "scripts" / "mutation_asp.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["mutation_asp"] = module
    spec.loader.exec_module(module)
    return module


PARAMS = (rules_path() / "params.lp").read_text(encoding="utf-8")
TOO_LOW = "too_low(T,I,N,V,M) :- step(T,I,P), fits_type(T,I,N), param_min(P,N,M), value_num(T,I,N,V), V < M."


def test_statements_are_found_at_their_lines_past_comments_and_strings(asp):
    found = {s.line: " ".join(s.text.split()) for s in asp.statements(PARAMS)}
    assert found[11] == TOO_LOW
    assert found[8] == 'fits_type(T,I,N) :- step(T,I,P), param(P,N,"decimal"), value_kind(T,I,N,"integer").'
    assert not any("thousandths" in text for text in found.values())  # '0.001' in a comment ends nothing
    assert len(found) == 10


def test_each_statement_is_deleted_each_literal_dropped_and_each_comparison_flipped(asp):
    changed = {(m.kind, m.after) for m, _ in asp.mutants("rules/params.lp", PARAMS) if m.before == TOO_LOW}
    assert ("delete rule", "(deleted)") in changed
    assert ("flip comparison", TOO_LOW.replace("V < M", "V <= M")) in changed
    assert ("drop literal", TOO_LOW.replace(" fits_type(T,I,N),", "")) in changed
    assert ("drop literal", TOO_LOW.replace(", V < M", "")) in changed
    assert len(changed) == 1 + 5 + 1


def test_comparisons_flip_both_ways(asp):
    rule = asp.Statement(1, 0, 0, "a(X) :- b(X,Y), X <= Y, X != Y, Y >= 2, #count{ Z : c(Z) } = 3.")
    flipped = {after for kind, after in asp.changes(rule) if kind == "flip comparison"}
    assert flipped == {
        "a(X) :- b(X,Y), X < Y, X != Y, Y >= 2, #count{ Z : c(Z) } = 3.",
        "a(X) :- b(X,Y), X <= Y, X = Y, Y >= 2, #count{ Z : c(Z) } = 3.",
        "a(X) :- b(X,Y), X <= Y, X != Y, Y > 2, #count{ Z : c(Z) } = 3.",
        "a(X) :- b(X,Y), X <= Y, X != Y, Y >= 2, #count{ Z : c(Z) } != 3.",
    }


def test_a_mutant_keeps_every_other_rule_at_its_line(asp):
    chain = (rules_path() / "chain.lp").read_text(encoding="utf-8")
    lines = [(s.line, " ".join(s.text.split())) for s in asp.statements(chain)]
    for mutant, text in asp.mutants("rules/chain.lp", chain):
        kept = [(s.line, " ".join(s.text.split())) for s in asp.statements(text)]
        assert [entry for entry in lines if entry[0] != mutant.line] == [k for k in kept if k[0] != mutant.line]
        assert mutant.where == f"rules/chain.lp:{mutant.line}"


def test_clingo_refuses_a_mutant_that_leaves_a_variable_unsafe(asp):
    by_change = {m.after: text for m, text in asp.mutants("rules/params.lp", PARAMS) if m.before == TOO_LOW}
    assert asp.refused(by_change[TOO_LOW.replace(" value_num(T,I,N,V),", "")])  # V is bound nowhere else
    assert not asp.refused(by_change[TOO_LOW.replace("V < M", "V <= M")])
    assert not asp.refused(PARAMS)


TINY = "a :- b, c.\nd :- a.\n"
CHECKS = '''from pathlib import Path


def test_tiny():
    text = (Path.cwd() / "rules" / "tiny.lp").read_text(encoding="utf-8")
    with open({log!r}, "a", encoding="utf-8") as log:
        log.write(" ".join(text.split()) + "\\n")
    assert {needed!r} in text
'''


def tiny_checkout(root: Path, log: Path, needed: str) -> None:
    """A checkout with one encoding (``rules/tiny.lp``) and one test that needs ``needed`` in it."""
    for name in ("src", "tests", "ontology", "rules", "descriptions"):
        (root / name).mkdir(parents=True, exist_ok=True)
    (root / "pyproject.toml").write_text("", encoding="utf-8")
    (root / "rules" / "tiny.lp").write_text(TINY, encoding="utf-8")
    (root / "tests" / "test_tiny.py").write_text(CHECKS.format(log=str(log), needed=needed), encoding="utf-8")


def test_a_listed_equivalent_is_never_run_and_again_runs_only_the_last_survivors(asp, tmp_path: Path) -> None:
    root, work, log = tmp_path / "checkout", tmp_path / "work", tmp_path / "runs.log"
    tiny_checkout(root, log, "d :- a.")
    target = asp.Target("rules-tiny", "rules/tiny.lp", ("tests/test_tiny.py",))
    listed = {("rules/tiny.lp", "a :- b, c.", "a :- c.")}

    def outcomes(again: bool) -> dict[tuple[str, str], str]:
        results = asp.run_target(target, root, work, 1, again, listed)
        return {(m.before, m.after): status for m, status in results.values()}

    assert outcomes(False) == {("a :- b, c.", "(deleted)"): "survived", ("a :- b, c.", "a :- b."): "survived",
                               ("a :- b, c.", "a :- c."): "survived", ("d :- a.", "(deleted)"): "killed",
                               ("d :- a.", "d :- ."): "killed"}
    ran = log.read_text(encoding="utf-8").splitlines()
    assert "a :- c. d :- a." not in ran  # the listed equivalent
    assert sorted(ran) == sorted(["a :- b, c. d :- a.", "d :- a.", "a :- b. d :- a.", "a :- b, c.",
                                  "a :- b, c. d :- ."])

    log.unlink()
    tiny_checkout(root, log, "a :- b, c.")  # a test that kills the two survivors, and the listed one if it ran
    again = outcomes(True)
    assert again[("a :- b, c.", "(deleted)")] == again[("a :- b, c.", "a :- b.")] == "killed"
    assert again[("a :- b, c.", "a :- c.")] == "survived" and again[("d :- a.", "(deleted)")] == "killed"
    assert sorted(log.read_text(encoding="utf-8").splitlines()) == sorted(["a :- b, c. d :- a.", "d :- a.",
                                                                           "a :- b. d :- a."])
