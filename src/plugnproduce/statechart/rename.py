"""Renaming a chart's datamodel variables and state ids inside every expression it holds.

When several charts become regions of one document (the closed-world simulation chart), each
chart's variables and states get a prefix so that they cannot clash. The declarations are the
easy part; every expression that reads or writes them must follow: conditions (``cond`` of a
transition, ``<if>``, ``<elseif>``), locations and values of ``<assign>``, ``<param>``, ``<data>``,
``<log>``, ``<foreach>``, the ``...expr`` and ``idlocation`` attributes of ``<send>``, ``<cancel>``
and ``<invoke>``, their ``namelist``s, and the state ids given to ``In()``.

Expressions are Python (the charts' ``datamodel="python"``): they are parsed with :mod:`ast` and
every name that is one of the chart's variables is replaced, wherever it stands (an attribute
name, a keyword or a string is no variable). An expression that is not valid Python is left as
written: the interpreter reports it where it is evaluated, as it would have.
"""

from __future__ import annotations

import ast
from collections.abc import Mapping

from plugnproduce.statechart.model import (
    Assign,
    Cancel,
    Content,
    Data,
    ElseIf,
    Foreach,
    If,
    Invoke,
    Log,
    Node,
    Param,
    Send,
    Transition,
    walk,
)

_EXPRESSIONS: dict[type[Node], tuple[str, ...]] = {
    Transition: ("cond",),
    If: ("cond",),
    ElseIf: ("cond",),
    Assign: ("location", "expr"),
    Param: ("expr", "location"),
    Data: ("expr",),
    Log: ("expr",),
    Content: ("expr",),
    Foreach: ("array", "item", "index"),
    Send: ("eventexpr", "targetexpr", "typeexpr", "idlocation", "delayexpr"),
    Cancel: ("sendidexpr",),
    Invoke: ("typeexpr", "srcexpr", "idlocation"),
}
"""The attributes of each element that hold an expression or a location."""


class _Renamer(ast.NodeTransformer):
    def __init__(self, variables: Mapping[str, str], states: Mapping[str, str]) -> None:
        self.variables, self.states, self.changed = variables, states, False

    def visit_Name(self, node: ast.Name) -> ast.Name:  # noqa: N802 - ast's visitor naming
        if node.id in self.variables:
            node.id, self.changed = self.variables[node.id], True
        return node

    def visit_Call(self, node: ast.Call) -> ast.AST:  # noqa: N802 - ast's visitor naming
        self.generic_visit(node)
        if isinstance(node.func, ast.Name) and node.func.id == "In" and len(node.args) == 1:
            arg = node.args[0]
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str) and arg.value in self.states:
                node.args[0], self.changed = ast.Constant(self.states[arg.value]), True
        return node


def renamed_expression(source: str, variables: Mapping[str, str], states: Mapping[str, str] | None = None) -> str:
    """``source`` with each variable of ``variables`` renamed, and each state id of ``states`` given to ``In()``
    renamed; unchanged (as written) when it names none of them or is no valid Python expression."""
    try:
        tree = ast.parse(source.strip(), mode="eval")
    except (SyntaxError, ValueError):
        return source
    renamer = _Renamer(variables, states or {})
    tree = renamer.visit(tree)
    return ast.unparse(tree) if renamer.changed else source


def rename_in(node: Node, variables: Mapping[str, str], states: Mapping[str, str] | None = None) -> None:
    """Rename, in place, the variables and ``In()`` state ids in every expression, location and namelist of
    ``node`` and the elements below it (not inside inline child charts, which have a datamodel of their own)."""
    for item in walk(node, into_charts=False):
        for name in _EXPRESSIONS.get(type(item), ()):
            value = getattr(item, name)
            if value:
                setattr(item, name, renamed_expression(value, variables, states))
        if isinstance(item, Send | Invoke) and item.namelist:
            item.namelist = [variables.get(n, n) for n in item.namelist]
