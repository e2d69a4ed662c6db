"""Executable content compiled to actions: small objects whose ``run(rt)`` does the work.

``rt`` is the running session, as :class:`~plugnproduce.statechart.runtime.session.ActionSession`
names it: actions use only its datamodel namespace ``rt.dm`` and a few methods (``holds``,
``raise_internal``, ``send``, ``cancel``, ``log``, ``new_sendid``). A failing action raises :class:`EvaluationError` or
:class:`ActionError`; the interpreter then stops the block and raises the error event.
"""

from __future__ import annotations

import ast
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from plugnproduce.errors import ExecutionError, PlugNProduceError
from plugnproduce.safeio import parse_xml_bytes
from plugnproduce.statechart.model import (
    Assign,
    Cancel,
    Chart,
    Content,
    DoneData,
    Executable,
    Foreach,
    If,
    Invoke,
    Log,
    Param,
    Raise,
    Script,
    Send,
)
from plugnproduce.statechart.runtime.evaluator import EvaluationError, Evaluator, Expr, Location
from plugnproduce.statechart.runtime.events import EventData

if TYPE_CHECKING:
    from plugnproduce.statechart.runtime.session import ActionSession


class ActionError(ExecutionError):
    """An action failed in a way the chart sees as ``kind`` (``error.execution`` or ``error.communication``)."""

    def __init__(self, message: str, kind: str = "error.execution", sendid: str | None = None):
        super().__init__(message)
        self.message = message
        self.kind = kind
        self.sendid = sendid


class Action:
    """One element of executable content, compiled."""

    __slots__ = ("line",)
    line: int | None  # the element's line in the chart

    def run(self, rt: ActionSession) -> None:
        """Do the action in the session ``rt``."""
        raise NotImplementedError


Block = tuple[Action, ...]
"""A sequence of actions that runs as a unit (an error stops the rest of it)."""


def run_actions(rt: ActionSession, block: Block) -> None:
    """Run a block's actions in order; errors propagate to the caller."""
    for action in block:
        action.run(rt)


# --- values ----------------------------------------------------------------------------


def literal(text: str) -> Any:
    """Inline text as a value: a Python literal if it is one, else the text with whitespace normalised."""
    stripped = text.strip()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SyntaxWarning)
            return ast.literal_eval(stripped)
    except (ValueError, SyntaxError, MemoryError, RecursionError):
        return " ".join(stripped.split())


def markup_value(markup: str) -> Any:
    """Inline markup as a value: the XML element when there is exactly one, else the markup text."""
    try:
        wrapper = parse_xml_bytes(f"<w>{markup}</w>".encode(), "<inline content>").getroot()
    except PlugNProduceError:
        return markup
    elements = [c for c in wrapper if isinstance(c.tag, str)]
    if len(elements) == 1 and not (wrapper.text or "").strip():
        return elements[0]
    return markup


class ValueSource:
    """Where a value comes from: an expression, inline text, inline markup or an inline chart."""

    __slots__ = ("expr", "value")

    def __init__(self, evaluator: Evaluator, expr: str | None, text: str | None, markup: str | None,
                 chart: Chart | None = None):
        self.expr: Expr | None = evaluator.expr(expr) if expr is not None else None
        self.value: Any = chart if chart is not None else (
            markup_value(markup) if markup is not None else (literal(text) if text is not None else None))

    def get(self, rt: ActionSession) -> Any:
        """The value now."""
        if self.expr is not None:
            return self.expr.evaluate(rt.dm)
        return self.value


def content_source(evaluator: Evaluator, content: Content | None) -> ValueSource | None:
    """The value source of a ``<content>`` (None when there is none)."""
    if content is None:
        return None
    return ValueSource(evaluator, content.expr, content.text, content.markup, content.chart)


@dataclass(slots=True)
class EventPayload:
    """How event data is built: ``namelist`` names and ``<param>`` values, or a ``<content>``."""

    names: list[tuple[str, Expr]] = field(default_factory=list)
    params: list[tuple[str, Expr]] = field(default_factory=list)
    content: ValueSource | None = None

    @classmethod
    def build(cls, evaluator: Evaluator, namelist: list[str], params: list[Param],
              content: Content | None) -> EventPayload:
        """Compile the payload parts."""
        return cls([(n, evaluator.expr(n)) for n in namelist],
                   [(p.name, evaluator.expr(p.expr if p.expr is not None else p.location or "None"))
                    for p in params],
                   content_source(evaluator, content))

    def evaluate(self, rt: ActionSession) -> Any:
        """The event data: the content's value, or a dict of names and params (None when empty)."""
        if self.content is not None:
            return self.content.get(rt)
        if not self.names and not self.params:
            return None
        data = EventData()
        for name, expr in self.names:
            if name not in rt.dm:
                raise EvaluationError(f"namelist names {name!r}, which is not in the datamodel")
            data[name] = expr.evaluate(rt.dm)
        for name, expr in self.params:
            data[name] = expr.evaluate(rt.dm)
        return data


_DELAY = re.compile(r"^\s*(\d+(?:\.\d*)?|\.\d+)\s*(ms|s|m|h)?\s*$")
_UNITS = {"ms": 0.001, "s": 1.0, "m": 60.0, "h": 3600.0, None: 1.0}


def parse_delay(text: str) -> float:
    """A CSS2-style duration (``300ms``, ``1.5s``, ``.5s``) in seconds."""
    m = _DELAY.match(str(text))
    if m is None:
        raise EvaluationError(f"delay {text!r} is not a duration; expected e.g. '300ms' or '1.5s'")
    return float(m.group(1)) * _UNITS[m.group(2)]


# --- actions ---------------------------------------------------------------------------


class RaiseAction(Action):
    __slots__ = ("event",)

    def __init__(self, node: Raise):
        self.event = node.event

    def run(self, rt: ActionSession) -> None:
        rt.raise_internal(self.event)


class SendAction(Action):
    __slots__ = ("event", "target", "type", "delay", "id", "idlocation", "payload")

    def __init__(self, ev: Evaluator, node: Send):
        self.event = _attr(ev, node.event, node.eventexpr)
        self.target = _attr(ev, node.target, node.targetexpr)
        self.type = _attr(ev, node.type, node.typeexpr)
        self.delay = _attr(ev, node.delay, node.delayexpr)
        self.id = node.id
        self.idlocation = ev.location(node.idlocation) if node.idlocation is not None else None
        self.payload = EventPayload.build(ev, node.namelist, node.params, node.content)

    def run(self, rt: ActionSession) -> None:
        sendid = self.id or rt.new_sendid()
        if self.idlocation is not None:
            self.idlocation.assign(rt.dm, sendid)
        try:
            name = value_of(rt, self.event)
            target = value_of(rt, self.target)
            kind = value_of(rt, self.type)
            delay = parse_delay(value_of(rt, self.delay)) if self.delay is not None else 0.0
            data = self.payload.evaluate(rt)
        except EvaluationError as exc:
            raise ActionError(str(exc), sendid=sendid) from exc
        visible = sendid if (self.id is not None or self.idlocation is not None) else None
        rt.send(str(name) if name is not None else "", target, kind, delay, data, sendid, visible)


class AssignAction(Action):
    __slots__ = ("location", "value")

    def __init__(self, ev: Evaluator, node: Assign):
        self.location = ev.location(node.location)
        self.value = ValueSource(ev, node.expr, node.text, node.markup)

    def run(self, rt: ActionSession) -> None:
        self.location.assign(rt.dm, self.value.get(rt))


class LogAction(Action):
    __slots__ = ("label", "expr")

    def __init__(self, ev: Evaluator, node: Log):
        self.label = node.label
        self.expr = ev.expr(node.expr) if node.expr is not None else None

    def run(self, rt: ActionSession) -> None:
        rt.log(self.label, self.expr.evaluate(rt.dm) if self.expr is not None else None)


class IfAction(Action):
    __slots__ = ("branches",)

    def __init__(self, ev: Evaluator, node: If, where: str):
        self.branches: list[tuple[Expr | None, Block]] = [(ev.expr(node.cond), compile_block(ev, node.actions, where))]
        for branch in node.elseifs:
            self.branches.append((ev.expr(branch.cond), compile_block(ev, branch.actions, where)))
        if node.orelse is not None:
            self.branches.append((None, compile_block(ev, node.orelse.actions, where)))

    def run(self, rt: ActionSession) -> None:
        for cond, block in self.branches:
            if cond is None or rt.holds(cond):
                run_actions(rt, block)
                return


class ForeachAction(Action):
    __slots__ = ("array", "item", "index", "block")

    def __init__(self, ev: Evaluator, node: Foreach, where: str):
        self.array = ev.expr(node.array)
        self.item = node.item
        self.index = node.index
        self.block = compile_block(ev, node.actions, where)

    def run(self, rt: ActionSession) -> None:
        array = self.array.evaluate(rt.dm)
        if not isinstance(array, list | tuple | dict | str | range):
            raise EvaluationError(f"foreach array {self.array.source!r} is a {type(array).__name__}; "
                                  "expected a list, tuple, dict or string")
        for name in (self.item, self.index):
            if name is not None and not _declarable(name):
                raise EvaluationError(f"foreach cannot use {name!r} as a variable name")
        for i, item in enumerate(list(array)):
            rt.dm[self.item] = item
            if self.index is not None:
                rt.dm[self.index] = i
            run_actions(rt, self.block)


class ScriptAction(Action):
    __slots__ = ("script",)

    def __init__(self, ev: Evaluator, node: Script, where: str):
        if node.src is not None:
            raise ExecutionError(f"{where}:{node.line}: <script src> is not supported; expected inline code")
        self.script = ev.script(node.text or "", f"{where}:{node.line}")

    def run(self, rt: ActionSession) -> None:
        self.script(rt.dm)


class CancelAction(Action):
    __slots__ = ("sendid",)

    def __init__(self, ev: Evaluator, node: Cancel):
        self.sendid = _attr(ev, node.sendid, node.sendidexpr)

    def run(self, rt: ActionSession) -> None:
        rt.cancel(str(value_of(rt, self.sendid)))


def _attr(ev: Evaluator, literal_value: str | None, expr: str | None) -> str | Expr | None:
    return ev.expr(expr) if expr is not None else literal_value


def value_of(rt: ActionSession, source: str | Expr | None) -> Any:
    """The value of a literal-or-expression attribute."""
    return source.evaluate(rt.dm) if isinstance(source, Expr) else source


def _declarable(name: str) -> bool:
    return name.isidentifier() and not name.startswith("__") and name not in ("_event", "_sessionid", "_name",
                                                                                  "_ioprocessors", "In")


_FACTORIES: dict[type, Callable[[Evaluator, Any, str], Action]] = {
    Raise: lambda ev, n, w: RaiseAction(n),
    Send: lambda ev, n, w: SendAction(ev, n),
    Assign: lambda ev, n, w: AssignAction(ev, n),
    Log: lambda ev, n, w: LogAction(ev, n),
    If: IfAction,
    Foreach: ForeachAction,
    Script: ScriptAction,
    Cancel: lambda ev, n, w: CancelAction(ev, n),
}


def compile_block(evaluator: Evaluator, actions: list[Executable], where: str) -> Block:
    """Compile executable content into a block of actions."""
    out = []
    for node in actions:
        action = _FACTORIES[type(node)](evaluator, node, where)
        action.line = node.line
        out.append(action)
    return tuple(out)


# --- done data and invoke ----------------------------------------------------------------


def compile_donedata(evaluator: Evaluator, done: DoneData | None, where: str) -> EventPayload | None:
    """The payload of a final state's ``<donedata>`` (None when it has none)."""
    if done is None:
        return None
    return EventPayload.build(evaluator, [], done.params, done.content)


@dataclass(slots=True)
class CInvoke:
    """An ``<invoke>`` ready to start."""

    node: Invoke
    type: str | Expr | None
    src: str | Expr | None
    idlocation: Location | None
    payload: EventPayload
    content: ValueSource | None
    finalize: Block


def compile_invoke(evaluator: Evaluator, node: Invoke, where: str) -> CInvoke:
    """Compile an ``<invoke>``: its type, source, data and finalize block."""
    return CInvoke(
        node=node,
        type=_attr(evaluator, node.type, node.typeexpr),
        src=_attr(evaluator, node.src, node.srcexpr),
        idlocation=evaluator.location(node.idlocation) if node.idlocation is not None else None,
        payload=EventPayload.build(evaluator, node.namelist, node.params, None),
        content=content_source(evaluator, node.content),
        finalize=compile_block(evaluator, node.finalize.actions, where) if node.finalize is not None else (),
    )
