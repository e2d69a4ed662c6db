"""The restricted evaluator bounds the memory an expression may build, before it builds it.

Each case runs in a child process capped at 1 GiB of address space, so that an evaluator without
the budget fails the test with a MemoryError instead of taking the machine's memory.
"""

from __future__ import annotations

import resource
import subprocess
import sys

import pytest

CAP = 1024**3
CHILD = """
import sys
from plugnproduce.statechart.runtime.evaluator import EvaluationError, Evaluator
e = Evaluator()
try:
    value = e.expr(sys.argv[1]).evaluate({"__builtins__": e.builtins()})
except EvaluationError as exc:
    print("refused:", exc)
else:
    print("value:", repr(value)[:60])
"""


def _cap() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (CAP, CAP))


def evaluate_capped(source: str) -> str:
    done = subprocess.run([sys.executable, "-c", CHILD, source], capture_output=True, text=True, timeout=300,
                          preexec_fn=_cap)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.strip()


@pytest.mark.parametrize("source, needle", [
    ("[[1]*10**6 for _ in range(10**6)]", "would make the expression build more than 4000000 items"),
    ("['a'*10**6 for _ in range(10**6)]", "would make the expression build more than 4000000 items"),
    ("[list(range(10**6)) for _ in range(10)]", "would make the expression build more than 4000000 items"),
    ("'%2000000000d' % 0", "a % format width or precision of 2000000000 would exceed"),
    ("'%-2000000000s' % 'x'", "a % format width or precision of 2000000000 would exceed"),
    ("'%*d' % (2000000000, 0)", "a % format width or precision of 2000000000 would exceed"),
    ("'%.2000000000f' % 1.5", "a % format width or precision of 2000000000 would exceed"),
    ("'%(a)2000000000d' % {'a': 1}", "a % format width or precision of 2000000000 would exceed"),
    ("b'%2000000000d' % 0", "a % format width or precision of 2000000000 would exceed"),
    ("[('ab'*500000) + ('ab'*500000) for _ in range(100)]", "would make the expression build more than"),
])
def test_issue_24_an_expression_that_would_build_too_much_is_refused_naming_it(source: str, needle: str) -> None:
    # [[1]*10**6 for _ in range(10**6)] reached 3.87 GB and '%2000000000d' % 0 1.99 GB
    said = evaluate_capped(source)
    assert said.startswith(f"refused: EvaluationError in {source!r}: "), said
    assert needle in said


@pytest.mark.parametrize("source, value", [
    ("'%5.2f|%-4s|%*d' % (3.14159, 'ab', 3, 7)", "' 3.14|ab  |  7'"),
    ("len([[0]*1000 for _ in range(1000)])", "1000"),
    ("'%s%%' % 50", "'50%'"),
    ("len('ab' * 500000 + 'cd')", "1000002"),
])
def test_expressions_within_the_budget_keep_their_python_value(source: str, value: str) -> None:
    assert evaluate_capped(source) == f"value: {value}"
