"""The Python datamodel: expressions compiled once, evaluated against a namespace dict.

By default expressions go through a **restricted** evaluator: the expression is parsed
with :mod:`ast` and only an allow-list of node types passes (no lambdas, no imports,
no walrus, no generator objects, no names or attributes that start with ``__`` or
``_`` respectively, no ``format``); calls are allowed only to a few safe builtins
(``len``, ``str``, ``hasattr``, ...), to ``In()`` and to an allow-list of data methods
(``get``, ``startswith``, ...). The namespace's ``__builtins__`` holds only those
builtins. A trusted evaluator (``trusted=True``) evaluates plain Python and runs
``<script>``.

An expression that does not compile, or that the restricted evaluator refuses, is
not a load error: like any failing expression it raises :class:`EvaluationError` when
evaluated, which the interpreter turns into ``error.execution`` (as the SCXML
specification asks). What a restricted expression may cost in time and memory is bounded by
:mod:`~plugnproduce.statechart.runtime.budgets`.
"""

from __future__ import annotations

import ast
import builtins
import functools
import textwrap
import warnings
from collections.abc import Callable
from typing import Any

from plugnproduce.errors import ExecutionError
from plugnproduce.statechart.runtime.budgets import GUARDS, Guard, allocation_left, steps_left
from plugnproduce.statechart.runtime.budgets import MAX_ALLOCATED as MAX_ALLOCATED
from plugnproduce.statechart.runtime.budgets import MAX_ITEMS as MAX_ITEMS
from plugnproduce.statechart.runtime.budgets import MAX_STEPS as MAX_STEPS
from plugnproduce.statechart.runtime.budgets import EvaluationError as EvaluationError

EXPRESSIONS_REMEMBERED = 4096
"""Compiled expressions kept for reuse (they depend only on their text and on trust)."""


SAFE_BUILTINS: dict[str, Any] = {
    name: getattr(builtins, name)
    for name in ("abs", "all", "any", "bool", "dict", "divmod", "enumerate", "float", "frozenset", "hasattr",
                 "int", "isinstance", "len", "list", "max", "min", "range", "repr", "reversed", "round", "set",
                 "sorted", "str", "sum", "tuple", "zip")
}
SAFE_BUILTINS.update({"True": True, "False": False, "None": None, "true": True, "false": False, "null": None})

MAX_SOURCE = 10_000
"""Longest expression an untrusted chart may hold (characters)."""
MAX_NODES = 2_000
"""Most syntax nodes in one untrusted expression."""

SAFE_METHODS = frozenset({
    "get", "keys", "values", "items", "copy", "count", "index", "append", "extend", "insert", "pop", "remove",
    "update", "setdefault", "clear", "startswith", "endswith", "lower", "upper", "strip", "lstrip", "rstrip",
    "split", "rsplit", "join", "replace", "find", "rfind", "isdigit", "isalpha", "isalnum", "isspace",
    "findall", "findtext", "iter", "getchildren",
})
"""Methods an untrusted expression may call (on data: dicts, lists, strings, XML elements)."""

_DENIED_ATTRS = frozenset({"format", "format_map", "mro"})

_ALLOWED_NODES: tuple[type[ast.AST], ...] = (
    ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.BinOp, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.FloorDiv,
    ast.Mod, ast.Pow, ast.LShift, ast.RShift, ast.BitOr, ast.BitXor, ast.BitAnd, ast.UnaryOp, ast.Not, ast.USub,
    ast.UAdd, ast.Invert, ast.Compare, ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.Is, ast.IsNot,
    ast.In, ast.NotIn, ast.IfExp, ast.Dict, ast.Set, ast.List, ast.Tuple, ast.Constant, ast.Name, ast.Load,
    ast.Store, ast.Attribute, ast.Subscript, ast.Slice, ast.Call, ast.keyword, ast.ListComp, ast.SetComp,
    ast.DictComp, ast.comprehension, ast.JoinedStr, ast.FormattedValue,
)


class Expr:
    """A compiled expression: ``evaluate(namespace)`` or :class:`EvaluationError`."""

    __slots__ = ("source", "code", "problem")

    def __init__(self, source: str, code: Any, problem: str | None):
        self.source = source
        self.code = code
        self.problem = problem

    def evaluate(self, namespace: dict[str, Any]) -> Any:
        """The expression's value in ``namespace``."""
        if self.code is None:
            raise EvaluationError(f"cannot evaluate {self.source!r}: {self.problem}")
        steps_left[0] = MAX_STEPS
        allocation_left[0] = MAX_ALLOCATED
        try:
            return eval(self.code, namespace)  # noqa: S307 - compiled from a checked AST (or trusted)
        except Exception as exc:
            raise EvaluationError(f"{type(exc).__name__} in {self.source!r}: {exc}") from exc


class Evaluator:
    """Compiles expressions, locations and scripts of one chart, restricted unless ``trusted``."""

    def __init__(self, trusted: bool = False):
        self.trusted = trusted

    def builtins(self) -> dict[str, Any]:
        """The ``__builtins__`` of a fresh namespace."""
        if self.trusted:
            return {**vars(builtins), "true": True, "false": False, "null": None}
        return {**SAFE_BUILTINS, **GUARDS}

    def expr(self, source: str) -> Expr:
        """Compile a value or condition expression (remembered: charts run again and again repeat them)."""
        return _compile_expression(source, self.trusted)

    def location(self, source: str) -> Location:
        """Compile an assignment location (a name, attribute or subscript)."""
        return Location(source, self)

    def script(self, source: str, where: str) -> Callable[[dict[str, Any]], None]:
        """Compile a ``<script>``; refused (:class:`ExecutionError`) unless trusted."""
        if not self.trusted:
            raise ExecutionError(f"{where}: <script> runs arbitrary code and is refused; create the interpreter "
                                 "with trusted=True to run it, and only for charts you trust")
        try:
            with warnings.catch_warnings():  # as for expressions
                warnings.simplefilter("ignore")
                code = compile(textwrap.dedent(source).strip("\n"), "<scxml script>", "exec")
        except SyntaxError as exc:
            problem = f"syntax error in <script> ({exc.msg})"

            def broken(namespace: dict[str, Any]) -> None:
                raise EvaluationError(problem)
            return broken

        def run(namespace: dict[str, Any]) -> None:
            try:
                exec(code, namespace)  # noqa: S102 - trusted charts only
            except Exception as exc:
                raise EvaluationError(f"{type(exc).__name__} in <script>: {exc}") from exc
        return run


PROTECTED = frozenset({"_event", "_sessionid", "_name", "_ioprocessors", "__builtins__", "In"})
"""Names a chart may read but not assign."""


class Location:
    """An assignable location: ``Var``, ``Var.attr``, ``Var[key]``."""

    __slots__ = ("source", "name", "container", "key", "attr", "problem")

    def __init__(self, source: str, evaluator: Evaluator):
        self.source = source
        self.name: str | None = None
        self.container: Expr | None = None
        self.key: Expr | None = None
        self.attr: str | None = None
        self.problem: str | None = None
        try:
            node = ast.parse(source.strip(), mode="eval").body
        except SyntaxError as exc:
            self.problem = f"syntax error ({exc.msg})"
            return
        if isinstance(node, ast.Name):
            self.name = node.id
        elif isinstance(node, ast.Attribute) and not node.attr.startswith("_"):
            self.container, self.attr = evaluator.expr(ast.unparse(node.value)), node.attr
        elif isinstance(node, ast.Subscript):
            self.container = evaluator.expr(ast.unparse(node.value))
            self.key = evaluator.expr(ast.unparse(node.slice))
        else:
            self.problem = "expected a name, an attribute or a subscript"

    def assign(self, namespace: dict[str, Any], value: Any) -> None:
        """Store ``value`` at the location; :class:`EvaluationError` when it cannot be done."""
        if self.problem is not None:
            raise EvaluationError(f"cannot assign to {self.source!r}: {self.problem}")
        if self.name is not None:
            if self.name in PROTECTED or self.name.startswith("__"):
                raise EvaluationError(f"cannot assign to {self.name!r}: it is read-only")
            if self.name not in namespace:
                raise EvaluationError(f"cannot assign to {self.name!r}: no such data in the datamodel")
            namespace[self.name] = value
            return
        assert self.container is not None  # set together with attr or key
        target = self.container.evaluate(namespace)
        try:
            if self.attr is not None and not isinstance(target, dict):
                setattr(target, self.attr, value)
            else:
                key = self.attr if self.attr is not None else self.key.evaluate(namespace)  # type: ignore[union-attr]
                target[key] = value
        except EvaluationError:
            raise
        except Exception as exc:
            raise EvaluationError(f"cannot assign to {self.source!r}: {exc}") from exc


def _compile(source: str, trusted: bool) -> Expr:
    try:
        if not trusted and len(source) > MAX_SOURCE:
            raise _Refused(f"the expression is {len(source)} characters long; at most {MAX_SOURCE} are allowed")
        # Python's advice on the chart's style (``x is 1``, ``'C:\data'``) is no error, whatever the warning filters
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tree = ast.parse(source.strip(), mode="eval")
            if not trusted:
                _check(tree)
                tree = ast.fix_missing_locations(Guard().visit(tree))
            return Expr(source, compile(tree, "<scxml>", "eval"), None)  # compiling warns again
    except SyntaxError as exc:
        return Expr(source, None, f"syntax error ({exc.msg})")
    except _Refused as exc:
        return Expr(source, None, f"not allowed by the restricted evaluator: {exc}")
    except (RecursionError, MemoryError):
        return Expr(source, None, "the expression is nested too deeply")


_compile_expression = functools.lru_cache(maxsize=EXPRESSIONS_REMEMBERED)(_compile)
# (wrapped rather than decorated, so that mutation testing reaches the checks in ``_compile``)


class _Refused(Exception):
    """An expression uses something the restricted evaluator does not allow."""


def _check(tree: ast.AST) -> None:
    for count, node in enumerate(ast.walk(tree), start=1):
        if count > MAX_NODES:
            raise _Refused(f"the expression has more than {MAX_NODES} parts")
        if not isinstance(node, _ALLOWED_NODES):
            raise _Refused(f"{type(node).__name__} is not allowed")
        if isinstance(node, ast.Name) and node.id.startswith("__"):
            raise _Refused(f"the name {node.id!r} is not allowed")
        if isinstance(node, ast.Attribute) and (node.attr.startswith("_") or node.attr in _DENIED_ATTRS):
            raise _Refused(f"the attribute {node.attr!r} is not allowed")
        if isinstance(node, ast.Call):
            _check_call(node)
        if isinstance(node, ast.FormattedValue) and node.format_spec is not None:
            raise _Refused("format specifications in f-strings are not allowed")


def _check_call(node: ast.Call) -> None:
    func = node.func
    if isinstance(func, ast.Name) and (func.id in SAFE_BUILTINS or func.id == "In"):
        return
    if isinstance(func, ast.Attribute) and func.attr in SAFE_METHODS:
        return
    raise _Refused(f"calling {ast.unparse(func)!r} is not allowed")
