"""The restricted evaluator's budgets: an untrusted chart's expression cannot cost unbounded time or memory.

Each hostile expression ends as an :class:`EvaluationError` (the chart gets ``error.execution``)
instead of hanging, exhausting memory or raising past the interpreter.
"""

from __future__ import annotations

import ast
import re

import pytest

from plugnproduce.statechart.runtime.evaluator import MAX_NODES, EvaluationError, Evaluator


def evaluate(source: str, **data: object) -> object:
    untrusted = Evaluator()  # built per call: what a device's chart gets
    return untrusted.expr(source).evaluate({"__builtins__": untrusted.builtins(), **data})


@pytest.mark.parametrize(("source", "needle"), [
    ("10**10**10", "exceed"),
    ("2 << 10**9", "exceed"),
    ("'a' * 10**10", "exceed"),
    ("[0] * 10**9", "exceed"),
    ("list(range(10**12))", "exceed"),
    ("[a * b for a in range(5000) for b in range(5000)]", "iterations"),
    ("s.replace('', s)", "exceed"),
    ("s.join([s, s, s, s, s, s, s, s, s, s, s, s])", "exceed"),
    ("f'{1:>999999999}'", "format specifications"),
    ("+".join(["1"] * 1000), "parts"),
    ("1" + "+1" * 20_000, "characters long"),
    ("(" * 5000 + "1" + ")" * 5000, "cannot evaluate"),
], ids=["power", "shift", "string", "list", "range", "iterations", "replace", "join", "format", "1000 terms",
        "long", "nested"])
def test_a_costly_expression_is_an_evaluation_error(source: str, needle: str) -> None:
    with pytest.raises(EvaluationError, match=needle):
        evaluate(source, s="ab" * 100_000)


def test_an_expression_of_as_many_parts_as_the_limit_is_evaluated_and_one_part_more_refused() -> None:
    items = MAX_NODES - 3  # a part per item, and the list, its context and the expression around them
    at_limit = f"[{', '.join(['1'] * items)}]"
    assert sum(1 for _ in ast.walk(ast.parse(at_limit, mode="eval"))) == MAX_NODES
    assert evaluate(at_limit) == [1] * items
    with pytest.raises(EvaluationError, match=f"the expression has more than {MAX_NODES} parts"):
        evaluate(f"[{', '.join(['1'] * (items + 1))}]")
    assert len(Evaluator(trusted=True).expr(at_limit + " + [1]").evaluate({})) == items + 1


def test_a_sum_too_deep_to_guard_is_refused_naming_it_though_short_and_of_few_parts() -> None:
    source = "+".join(["1"] * 600)  # 1199 characters, 1799 parts: within both limits
    with pytest.raises(EvaluationError, match=r"^cannot evaluate '1\+1\+1.*\+1': the expression is nested too deeply$"):
        evaluate(source)
    assert Evaluator(trusted=True).expr(source).evaluate({}) == 600


@pytest.mark.parametrize(("source", "value"), [
    ("2**10", 1024),
    ("(-3) ** 3", -27),
    ("2 ** -1", 0.5),
    ("1 << 8", 256),
    ("'ab' * 3", "ababab"),
    ("3 * [0]", [0, 0, 0]),
    ("[x * 2 for x in range(3)]", [0, 2, 4]),
    ("{k: v for k, v in zip('ab', range(2))}", {"a": 0, "b": 1}),
    ("','.join(['a', 'b'])", "a,b"),
    ("'abc'.replace('b', 'x')", "axc"),
    ("sum(range(1000))", 499500),
])
def test_ordinary_expressions_keep_their_values(source: str, value: object) -> None:
    assert evaluate(source) == value


def test_a_trusted_evaluator_is_not_budgeted() -> None:
    trusted = Evaluator(trusted=True)
    assert trusted.expr("len('a' * 2_000_000)").evaluate({"__builtins__": trusted.builtins()}) == 2_000_000


@pytest.mark.parametrize(("source", "needle"), [
    ("['a'*10**6 for _ in range(10)]", "build more than 4000000 items and characters in all"),
    ("[s + s for _ in range(100)]", "joining sequences of 200000 and 200000 items would make"),
    ("[s.replace('a', 'bb') for _ in range(100)]", "this replace would make"),
    ("['-'.join([s, s]) for _ in range(100)]", "joining these strings would make"),
    ("'%2000000000d' % 0", "a % format width or precision of 2000000000 would exceed"),
    ("'%.*f' % (2000000000, 1.5)", "a % format width or precision of 2000000000 would exceed"),
    ("'%*d' % ('x', 0)", "a % format width or precision of 'x' would exceed"),
], ids=["rows", "concatenations", "replaces", "joins", "width", "star precision", "star not a number"])
def test_what_an_evaluation_builds_in_all_is_bounded_before_it_is_built(source: str, needle: str) -> None:
    with pytest.raises(EvaluationError, match=re.escape(needle)):
        evaluate(source, s="ab" * 100_000)


@pytest.mark.parametrize(("source", "value"), [
    ("'%d %*d|%-3s|%.1f' % (1, 4, 2, 'a', 2.25)", "1    2|a  |2.2"),
    ("'%(n)5d' % {'n': 7}", "    7"),
    ("'100%%' % ()", "100%"),
    ("len([s + 'x' for _ in range(10)])", 10),
    ("3 % 2 + 4", 5),
])
def test_formatting_and_sums_within_the_budget_are_python_s(source: str, value: object) -> None:
    assert evaluate(source, s="ab") == value
