"""The restricted evaluator's allow-list: what an untrusted chart's expression can never do.

A device's chart comes from the network. Its expressions run in the controller, so each
test here is an attack a chart could carry: reading a file, reaching a class or a module
through attributes, calling ``format`` to walk attributes by a format string, calling the
evaluator's own guard functions, or smuggling in a lambda, a generator or a walrus. Each is
refused before anything of it runs, and the file's content never reaches the chart.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from types import SimpleNamespace

import pytest

from plugnproduce.statechart import SCXML_NS, parse_chart
from plugnproduce.statechart.runtime.evaluator import MAX_ITEMS, MAX_STEPS, EvaluationError, Evaluator
from plugnproduce.statechart.runtime.events import ERROR, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter

TRUSTED = True
"""Evaluate as for a chart the user trusts (plain Python)."""

# Reaches ``__import__`` from nothing but an empty tuple: it reads the file in a plain eval sandbox.
ESCAPE = ("[c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'catch_warnings'][0]()"
          "._module.__builtins__['__import__']('pathlib').Path(path).read_text()")


@pytest.fixture
def secret(tmp_path: Path) -> Path:
    path = tmp_path / "secret.txt"
    path.write_text("the controller's secret", encoding="utf-8")
    return path


def evaluate(source: str, trusted: bool = False, **data: object) -> object:
    """The value of ``source`` in a fresh namespace: restricted as for a device's chart unless ``trusted``."""
    evaluator = Evaluator(trusted=True) if trusted else Evaluator()
    return evaluator.expr(source).evaluate({"__builtins__": evaluator.builtins(), **data})


def test_the_escape_reads_the_file_when_the_chart_is_trusted(secret: Path) -> None:
    assert evaluate(ESCAPE, TRUSTED, path=str(secret)) == "the controller's secret"


@pytest.mark.parametrize("source", [
    ESCAPE,
    "().__class__.__base__.__subclasses__()",
    "__builtins__",
    "__import__('os').listdir('.')",
    "open(path).read()",
], ids=["escape", "dunder attribute", "dunder name", "import", "open"])
def test_an_untrusted_expression_cannot_reach_a_file(source: str, secret: Path) -> None:
    with pytest.raises(EvaluationError, match="not allowed by the restricted evaluator"):
        evaluate(source, path=str(secret))


@pytest.mark.parametrize("source", [
    "'{0.__class__.__mro__}'.format(x)",
    "'{x.__class__}'.format_map({'x': x})",
    "max([x], key='{0.__class__.__mro__}'.format)",
    "sorted([x], key='{0.__init__.__globals__}'.format_map)",
    "str.mro",
], ids=["format", "format_map", "format as key", "format_map as key", "mro"])
def test_an_untrusted_expression_cannot_walk_attributes_through_format(source: str) -> None:
    with pytest.raises(EvaluationError, match="not allowed by the restricted evaluator"):
        evaluate(source, x=SimpleNamespace())


def test_format_walks_attributes_when_the_chart_is_trusted() -> None:
    assert "object" in str(evaluate("'{0.__class__.__mro__}'.format(x)", TRUSTED, x=1))


@pytest.mark.parametrize("source", [
    "__pnp_method('{0.__class__}', 'format', 1)",
    "__pnp_binop('Pow', 10, 10)",
    "box._hidden",
], ids=["guard method", "guard binop", "underscore attribute"])
def test_an_untrusted_expression_cannot_name_the_guards_or_private_attributes(source: str) -> None:
    with pytest.raises(EvaluationError, match="not allowed by the restricted evaluator"):
        evaluate(source, box=SimpleNamespace(_hidden=1))


@pytest.mark.parametrize("source", [
    "lambda: 0",
    "(x for x in seen)",
    "(y := 3)",
    "[*seen]",
    "seen.append(1) or (lambda: 0)",
], ids=["lambda", "generator", "walrus", "starred", "lambda after a side effect"])
def test_syntax_outside_the_allow_list_is_refused_before_anything_runs(source: str) -> None:
    seen: list[int] = []
    with pytest.raises(EvaluationError, match="not allowed by the restricted evaluator"):
        evaluate(source, seen=seen)
    assert seen == []


@pytest.mark.parametrize("source", ["'a'.ljust(10**7)", "'ab'.encode()", "box.method()", "getattr(box, 'method')()",
                                    "vars()"])
def test_calls_outside_the_allow_list_are_refused(source: str) -> None:
    box = SimpleNamespace(method=lambda: "called")
    with pytest.raises(EvaluationError, match="not allowed by the restricted evaluator"):
        evaluate(source, box=box)


@pytest.mark.parametrize(("source", "value"), [
    ("len(d) + abs(-1)", 3),
    ("sorted(d.keys())", ["a", "b"]),
    ("d.get('a', 0) + d['b']", 3),
    ("'Grip'.lower().startswith('gr')", True),
    ("In('s')", True),
    ("f'{d[\"a\"]}-{len(d)}'", "1-2"),
    ("[k for k in d if k != 'a']", ["b"]),
    ("true and not false and null is None", True),
])
def test_allowed_builtins_methods_and_in_still_work(source: str, value: object) -> None:
    assert evaluate(source, d={"a": 1, "b": 2}, In=lambda state: state == "s") == value


def test_an_expression_at_the_length_limit_is_accepted_and_one_longer_refused() -> None:
    at_limit = "1" + " " * 9_999
    assert evaluate(at_limit) == 1
    with pytest.raises(EvaluationError, match="at most 10000"):
        evaluate(at_limit + " ")
    assert evaluate(at_limit + " ", TRUSTED) == 1


@pytest.mark.parametrize("trusted", [False, True], ids=["untrusted", "trusted"])
@pytest.mark.parametrize(("source", "value"), [
    ("x is 1", True),  # SyntaxWarning: "is" with a literal
    ("'C:\\data'", "C:\\data"),  # an invalid escape: DeprecationWarning (SyntaxWarning from Python 3.12)
], ids=["is literal", "invalid escape"])
def test_an_expression_python_warns_about_evaluates_without_a_warning(source: str, value: object,
                                                                     trusted: bool) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # as ``python -W error`` would: a warning must not even be raised
        assert evaluate(source, trusted, x=1) == value


def test_a_refused_expression_names_itself_and_what_is_not_allowed() -> None:
    with pytest.raises(EvaluationError, match=r"^cannot evaluate 'open\(path\)': not allowed by the restricted "
                                              r"evaluator: calling 'open' is not allowed$"):
        evaluate("open(path)", path="secret.txt")


def test_a_trusted_chart_may_write_true_false_and_null_as_its_untrusted_expressions_may() -> None:
    assert evaluate("[true, false, null]", TRUSTED) == evaluate("[true, false, null]") == [True, False, None]


def test_an_expression_that_fails_when_evaluated_names_itself_and_the_error() -> None:
    with pytest.raises(EvaluationError, match=r"^ZeroDivisionError in 'x / 0': division by zero$"):
        evaluate("x / 0", x=1)


def test_a_syntax_error_is_an_evaluation_error_naming_it() -> None:
    with pytest.raises(EvaluationError, match=r"cannot evaluate '1 \+': syntax error"):
        evaluate("1 +")


# --- assignments -------------------------------------------------------------------------


def session(body: str) -> tuple[Interpreter, list[MetaEvent]]:
    text = f'<scxml xmlns="{SCXML_NS}" version="1.0" datamodel="python">{body}</scxml>'
    interpreter = Interpreter(parse_chart(text.encode(), "test chart"))
    errors: list[MetaEvent] = []
    interpreter.attach(lambda meta: errors.append(meta) if meta.name == ERROR else None)
    interpreter.start()
    return interpreter, errors


@pytest.mark.parametrize(("location", "needle"), [
    ("_event", "read-only"),
    ("In", "read-only"),
    ("__builtins__", "read-only"),
    ("__pnp_iter", "read-only"),
    ("missing", "no such data"),
    ("box._hidden", "cannot assign to 'box._hidden': expected a name, an attribute or a subscript$"),
    ("box +", "syntax error"),
])
def test_a_chart_cannot_assign_to_protected_or_unknown_names(location: str, needle: str) -> None:
    interpreter, errors = session(f"""
    <datamodel><data id="box" expr="{{'_hidden': 1}}"/></datamodel>
    <state id="s"><onentry><assign location="{location}" expr="1"/></onentry>
      <transition event="error.execution" target="refused"/></state>
    <state id="refused"/>""")
    assert interpreter.is_active("refused")
    assert re.search(needle, errors[0].data["event"].data["message"])
    assert interpreter.datamodel["box"] == {"_hidden": 1}


def test_assigning_in_place_reaches_attributes_and_subscripts() -> None:
    interpreter, errors = session("""
    <datamodel><data id="box" expr="{'a': 1, 'items': [0, 0]}"/></datamodel>
    <state id="s"><onentry>
      <assign location="box.a" expr="2"/><assign location="box['b']" expr="3"/>
      <assign location="box['items'][1]" expr="4"/>
    </onentry></state>""")
    assert errors == []
    assert interpreter.datamodel["box"] == {"a": 2, "b": 3, "items": [0, 4]}


def test_assigning_to_a_missing_key_of_a_list_is_an_execution_error() -> None:
    interpreter, errors = session("""
    <datamodel><data id="items" expr="[0]"/></datamodel>
    <state id="s"><onentry><assign location="items[5]" expr="1"/></onentry></state>""")
    assert "cannot assign to 'items[5]'" in errors[0].data["event"].data["message"]
    assert interpreter.datamodel["items"] == [0]


def test_a_location_assigns_to_an_attribute_of_an_object_and_to_a_computed_key() -> None:
    box, table = SimpleNamespace(size=1), {"k": 0}
    namespace = {"box": box, "table": table, "key": "k"}
    Evaluator().location("box.size").assign(namespace, 3)
    Evaluator().location("table[key]").assign(namespace, 4)
    assert (box.size, table) == (3, {"k": 4})


# --- the budgets of join and replace, at their limits ------------------------------------


def test_join_may_build_up_to_the_limit_and_not_beyond() -> None:
    half = "a" * (MAX_ITEMS // 2)
    assert len(evaluate("''.join([s, s])", s=half)) == MAX_ITEMS  # type: ignore[arg-type]
    with pytest.raises(EvaluationError, match="exceed"):
        evaluate("''.join([s, s, 'a'])", s=half)


def test_a_long_separator_counts_once_per_part() -> None:
    with pytest.raises(EvaluationError, match="exceed"):
        evaluate("sep.join(['a', 'b', 'c'])", sep="-" * (MAX_ITEMS // 3))
    assert evaluate("sep.join([])", sep="-" * (MAX_ITEMS // 3)) == ""
    assert evaluate("'-'.join([x for x in 'abc'])") == "a-b-c"


def test_join_and_replace_take_the_arguments_python_takes() -> None:
    with pytest.raises(EvaluationError, match="TypeError"):
        evaluate("'-'.join(['a'], 'b')")
    try:
        value = evaluate("'aaa'.replace('a', 'b', count=1)")
    except EvaluationError:
        value = None  # Python before 3.13 takes no keywords here
    assert value in ("baa", None)


def test_replace_may_build_up_to_the_limit_and_not_beyond() -> None:
    assert len(evaluate("''.replace('', new)", new="x" * MAX_ITEMS)) == MAX_ITEMS  # type: ignore[arg-type]
    with pytest.raises(EvaluationError, match="exceed"):
        evaluate("'ab'.replace('', new)", new="x" * (MAX_ITEMS // 2))


@pytest.mark.parametrize("source", ["b.replace(b'', b)", "b''.join([b] * 100)", "b'-'.join([b'x'] * 600000)"])
def test_bytes_are_budgeted_like_strings(source: str) -> None:
    with pytest.raises(EvaluationError, match="exceed"):
        evaluate(source, b=b"x" * 20_000)


def test_comprehensions_may_take_up_to_the_limit_of_iterations_and_not_one_more() -> None:
    assert evaluate("len([1 for a in range(1000) for b in range(999)])") == 999_000  # 1,000 + 999,000 iterations
    with pytest.raises(EvaluationError, match=f"more than {MAX_STEPS} iterations"):
        evaluate("len([1 for a in range(1000) for b in range(1000)])")


def test_range_may_be_as_long_as_the_limit_and_not_longer() -> None:
    assert evaluate(f"len(range({MAX_ITEMS}))") == MAX_ITEMS
    with pytest.raises(EvaluationError, match="exceed"):
        evaluate(f"range({MAX_ITEMS + 1})")


@pytest.mark.parametrize(("source", "value"), [("1 ** 1000000", 1), ("(-1) ** 1000001", -1), ("0 ** 1000000", 0),
                                             ("2 ** 65536 == 1 << 65536", True), ("(-2) ** 3", -8)])
def test_a_power_whose_result_is_small_enough_is_computed(source: str, value: object) -> None:
    assert evaluate(source) == value


@pytest.mark.parametrize("source", ["2 ** 65537", "(-2) ** 65537", "10 ** 30000", "3 ** 70000"])
def test_a_power_whose_result_would_be_too_large_is_refused(source: str) -> None:
    with pytest.raises(EvaluationError, match=r"\*\* .* would exceed"):
        evaluate(source)


def test_a_sequence_may_be_repeated_up_to_the_limit_and_not_beyond() -> None:
    assert len(evaluate(f"'a' * {MAX_ITEMS}")) == MAX_ITEMS  # type: ignore[arg-type]
    with pytest.raises(EvaluationError, match="exceed"):
        evaluate(f"[0] * {MAX_ITEMS + 1}")


@pytest.mark.parametrize(("source", "shown"), [("(2 ** 63) ** 2000", "9223372036854775808 ** 2000"),
                                               ("(2 ** 64) ** 2000", "a 65-bit integer ** 2000")])
def test_a_refused_power_names_an_operand_of_up_to_64_bits_by_its_value(source: str, shown: str) -> None:
    with pytest.raises(EvaluationError, match=re.escape(shown) + " would exceed"):
        evaluate(source)


def test_a_power_is_refused_by_the_size_of_its_result_even_to_the_first() -> None:
    assert evaluate("(1 << 60000) ** 1 == 1 << 60000") is True
    with pytest.raises(EvaluationError, match="a 120001-bit integer \\*\\* 1 would exceed"):
        evaluate("((1 << 60000) * (1 << 60000)) ** 1")
    with pytest.raises(EvaluationError, match="shifting left by a 120001-bit integer would exceed"):
        evaluate("1 << ((1 << 60000) * (1 << 60000))")


# --- <script>, for trusted charts only ----------------------------------------------------


def test_a_trusted_script_runs_whatever_its_indentation_and_first_name() -> None:
    run = Evaluator(trusted=True).script("\n    X = 7\n    y = X * 6\n", "chart")
    namespace: dict[str, object] = {}
    run(namespace)
    assert (namespace["X"], namespace["y"]) == (7, 42)


def test_a_trusted_script_whose_first_line_is_indented_deeper_is_an_indentation_error() -> None:
    run = Evaluator(trusted=True).script("\n    x = 1\n  y = 2\n", "chart")
    with pytest.raises(EvaluationError, match="syntax error in <script> \\(unexpected indent\\)"):
        run({})


def test_a_trusted_script_python_warns_about_still_runs() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # as ``python -W error`` would: a warning must not even be raised
        run = Evaluator(trusted=True).script("same = 1 is 1\npath = 'C:\\data'", "chart")  # "is" with a literal, '\d'
    namespace: dict[str, object] = {}
    run(namespace)
    assert (namespace["same"], namespace["path"]) == (True, "C:\\data")


def test_a_warning_of_a_trusted_chart_names_the_expression_or_the_script_it_came_from() -> None:
    trusted = Evaluator(trusted=True)
    with pytest.warns(UserWarning, match="careful") as caught:
        trusted.expr("__import__('warnings').warn('careful')").evaluate({})
        trusted.script("import warnings\nwarnings.warn('careful')", "chart")({})
    assert [(w.filename, w.lineno) for w in caught] == [("<scxml>", 1), ("<scxml script>", 2)]


def test_a_trusted_script_with_a_syntax_error_fails_when_run_naming_it() -> None:
    run = Evaluator(trusted=True).script("x = (", "chart")
    with pytest.raises(EvaluationError, match=r"syntax error in <script> \('\(' was never closed\)"):
        run({})
