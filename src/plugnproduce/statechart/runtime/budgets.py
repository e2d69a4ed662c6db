"""The budgets of untrusted expressions: what one evaluation may compute and build, checked before it does.

The restricted evaluator's allow-list (:mod:`~plugnproduce.statechart.runtime.evaluator`) keeps an
untrusted expression from reaching anything; these guards keep it from costing unbounded time or
memory. The operators that can blow up (``**``, ``*``, ``<<``), the string methods that multiply
their input (``join``, ``replace``) and ``range`` are checked before they compute, and every
comprehension draws its iterations from one budget per evaluation. :class:`Guard` rewrites a
checked expression so that those operations go through the guards; the guard names start with
``__``, which no checked expression may name.
"""

from __future__ import annotations

import ast
import re
from typing import Any

from plugnproduce.errors import ExecutionError


class EvaluationError(ExecutionError):
    """An expression could not be evaluated (the interpreter raises ``error.execution``)."""


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

steps_left = [MAX_STEPS]
"""Comprehension iterations the current evaluation may still take (reset by each evaluation)."""
allocation_left = [MAX_ALLOCATED]
"""Items and characters the current evaluation may still build (reset by each evaluation)."""


def _charge(size: int, what: str) -> None:
    """Count ``size`` items about to be built against the evaluation's allocation budget."""
    allocation_left[0] -= size
    if allocation_left[0] < 0:
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
        steps_left[0] -= 1
        if steps_left[0] < 0:
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


GUARDS: dict[str, Any] = {"__pnp_binop": _binop, "__pnp_iter": _iterate, "__pnp_method": _method, "range": _range}
_GUARDED_OPS = (ast.Pow, ast.Mult, ast.LShift, ast.Add, ast.Mod)
_GUARDED_METHODS = frozenset({"join", "replace"})


def _guard_call(name: str, *args: ast.expr, keywords: list[ast.keyword] | None = None) -> ast.Call:
    return ast.Call(func=ast.Name(id=name, ctx=ast.Load()), args=list(args), keywords=keywords or [])


class Guard(ast.NodeTransformer):
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
