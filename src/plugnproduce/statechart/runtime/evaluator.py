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
specification asks).
"""

from __future__ import annotations

import ast
import builtins
import functools
import re
import textwrap
import warnings
from collections.abc import Callable
from typing import Any

from plugnproduce.errors import ExecutionError

EXPRESSIONS_REMEMBERED = 4096
"""Compiled expressions kept for reuse (they depend only on their text and on trust)."""


class EvaluationError(ExecutionError):
    """An expression could not be evaluated (the interpreter raises ``error.execution``)."""


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
MAX_ITEMS = 1_000_000
"""Largest sequence (characters or items) an untrusted expression may build, and its longest ``range``."""
MAX_INT_BITS = 65_536
"""Largest integer (in bits) an untrusted ``**`` or ``<<`` may produce."""
MAX_STEPS = 1_000_000
"""Most comprehension iterations one untrusted evaluation may take."""
MAX_ALLOCATED = 4_000_000
"""Most items and characters one untrusted evaluation may build in all (repetitions, concatenations, ranges,
joins, replaces, ``%`` widths), counted before each is built: ``[[1]*10**6 for _ in range(10**6)]`` is refused
at its second row, not after gigabytes."""

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
        _steps[0] = MAX_STEPS
        _allocated[0] = MAX_ALLOCATED
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
        return {**SAFE_BUILTINS, **_GUARDS}

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
                tree = ast.fix_missing_locations(_Guard().visit(tree))
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


# ---------------------------------------------------------------- budgets of untrusted expressions
#
# The allow-list keeps an untrusted expression from reaching anything; these guards keep it
# from costing unbounded time or memory. The operators that can blow up (``**``, ``*``, ``<<``),
# the string methods that multiply their input (``join``, ``replace``) and ``range`` are
# checked before they compute, and every comprehension draws its iterations from one budget
# per evaluation. The guard names start with ``__``, which no checked expression may name.

_steps = [MAX_STEPS]
_allocated = [MAX_ALLOCATED]


def _charge(size: int, what: str) -> None:
    """Count ``size`` items about to be built against the evaluation's allocation budget."""
    _allocated[0] -= size
    if _allocated[0] < 0:
        raise EvaluationError(f"{what} would make the expression build more than {MAX_ALLOCATED} items and "
                              "characters in all, the restricted evaluator's limit")


def _too_large(what: str) -> EvaluationError:
    return EvaluationError(f"{what} would exceed the restricted evaluator's limits")


def _shown(value: Any) -> str:
    """An operand as a message names it: an integer too long to print, by its size."""
    if isinstance(value, int) and value.bit_length() > 64:
        return f"a {value.bit_length()}-bit integer"
    return repr(value)


def _size(value: Any) -> int | None:
    return len(value) if isinstance(value, str | bytes | list | tuple) else None


def _binop(op: str, left: Any, right: Any) -> Any:
    if op == "Pow":
        if (isinstance(left, int) and isinstance(right, int) and right > 0 and abs(left) > 1
                and right * max(abs(left).bit_length() - 1, 1) > MAX_INT_BITS):
            raise _too_large(f"{_shown(left)} ** {_shown(right)}")
        return left**right
    if op == "LShift":
        if isinstance(right, int) and right > MAX_INT_BITS:
            raise _too_large(f"shifting left by {_shown(right)}")
        return left << right
    if op == "Add":
        if (size := _size(left)) is not None and (other := _size(right)) is not None:
            _charge(size + other, f"joining sequences of {size} and {other} items")
        return left + right
    if op == "Mod":
        if isinstance(left, str | bytes):
            _charge(len(left) + _format_widths(left, right), "this % formatting")
        return left % right
    for seq, times in ((left, right), (right, left)):  # Mult
        size = _size(seq)
        if size is not None and isinstance(times, int):
            if size * times > MAX_ITEMS:
                raise _too_large(f"a sequence of {size} items repeated {times} times")
            _charge(size * times, f"a sequence of {size} items repeated {times} times")
    return left * right


_CONVERSION = re.compile(r"%(?:\([^)]*\))?[-#0 +]*(\*|\d+)?(?:\.(\*|\d+))?[hlL]?[a-zA-Z%]")


def _format_widths(template: str | bytes, values: Any) -> int:
    """The characters the widths and precisions of a ``%`` template ask for (a ``*`` takes its value from
    ``values``); refused when one is beyond :data:`MAX_ITEMS`, before anything is formatted."""
    text = template if isinstance(template, str) else template.decode("latin-1")
    given = list(values) if isinstance(values, tuple) else [values]
    total, taken = 0, 0
    for m in _CONVERSION.finditer(text):
        for part in (m.group(1), m.group(2)):
            if part == "*":
                width, taken = (given[taken] if taken < len(given) else 0), taken + 1
            else:
                width = int(part) if part else 0
            if not isinstance(width, int) or abs(width) > MAX_ITEMS:
                raise _too_large(f"a % format width or precision of {_shown(width)}")
            total += abs(width)
        taken += not m.group(0).endswith("%")
    return total


def _iterate(iterable: Any) -> Any:
    for item in iterable:
        _steps[0] -= 1
        if _steps[0] < 0:
            raise _too_large(f"more than {MAX_STEPS} iterations")
        yield item


def _method(target: Any, name: str, *args: Any, **kwargs: Any) -> Any:
    if isinstance(target, str | bytes) and name == "join" and args:  # bytes too: b''.join and b.replace multiply
        parts = list(_iterate(args[0]))
        size = sum(len(p) if isinstance(p, str | bytes) else 0 for p in parts) + len(target) * len(parts)
        if size > MAX_ITEMS:
            raise _too_large("joining these strings")
        _charge(size, "joining these strings")
        args = (parts, *args[1:])
    if isinstance(target, str | bytes) and name == "replace" and len(args) >= 2 and isinstance(args[1], str | bytes):
        size = len(target) + (len(target) + 1) * len(args[1])
        if size > MAX_ITEMS:
            raise _too_large("this replace")
        _charge(size, "this replace")
    return getattr(target, name)(*args, **kwargs)


def _range(*args: int) -> range:
    r = range(*args)
    try:
        if len(r) <= MAX_ITEMS:
            _charge(len(r), f"range{args}")
            return r
    except OverflowError:
        pass
    raise _too_large(f"range{args}")


_GUARDS: dict[str, Any] = {"__pnp_binop": _binop, "__pnp_iter": _iterate, "__pnp_method": _method, "range": _range}
_GUARDED_OPS = (ast.Pow, ast.Mult, ast.LShift, ast.Add, ast.Mod)
_GUARDED_METHODS = frozenset({"join", "replace"})


def _guard_call(name: str, *args: ast.expr, keywords: list[ast.keyword] | None = None) -> ast.Call:
    return ast.Call(func=ast.Name(id=name, ctx=ast.Load()), args=list(args), keywords=keywords or [])


class _Guard(ast.NodeTransformer):
    """Rewrites a checked expression so that its costly operations go through the guards."""

    def visit_BinOp(self, node: ast.BinOp) -> ast.expr:  # noqa: N802 - ast's visitor naming
        self.generic_visit(node)
        if not isinstance(node.op, _GUARDED_OPS):
            return node
        return ast.copy_location(
            _guard_call("__pnp_binop", ast.Constant(type(node.op).__name__), node.left, node.right), node)

    def visit_comprehension(self, node: ast.comprehension) -> ast.comprehension:
        self.generic_visit(node)
        node.iter = _guard_call("__pnp_iter", node.iter)
        return node

    def visit_Call(self, node: ast.Call) -> ast.expr:  # noqa: N802 - ast's visitor naming
        self.generic_visit(node)
        func = node.func
        if not (isinstance(func, ast.Attribute) and func.attr in _GUARDED_METHODS):
            return node
        call = _guard_call("__pnp_method", func.value, ast.Constant(func.attr), *node.args, keywords=node.keywords)
        return ast.copy_location(call, node)
