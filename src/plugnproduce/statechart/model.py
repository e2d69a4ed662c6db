"""A neutral model of a W3C SCXML 1.0 document, as plain dataclasses.

The reader (:mod:`plugnproduce.statechart.io.reader`) turns a document into a :class:`Chart`,
the writer (:mod:`plugnproduce.statechart.io.writer`) turns one back into XML, and the
interpreter (:mod:`plugnproduce.statechart.runtime.interpreter`) runs one. Expressions stay
strings here; nothing is evaluated.

Every node keeps its source ``line`` (ignored when nodes are compared) and
``extra_attrs``: attributes in foreign namespaces, keyed in Clark notation
(``{http://plugnproduce.org/ontology#}concept``), so annotations such as ``pnp:concept``
survive a read and a write.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import field
from typing import TypeAlias

from plugnproduce.deferred import dataclass

SCXML_NS = "http://www.w3.org/2005/07/scxml"
"""The SCXML namespace."""

PNP_NS = "http://plugnproduce.org/ontology#"
"""The project's ontology namespace (prefix ``pnp``)."""

CONCEPT = "{" + PNP_NS + "}concept"
"""Clark name of the ``pnp:concept`` annotation on states."""


def pnp(name: str) -> str:
    """The Clark name of a ``pnp:`` annotation attribute (``pnp("device")``)."""
    return "{" + PNP_NS + "}" + name


@dataclass(kw_only=True)
class Node:
    """What every element of the model has: its source line and foreign-namespace attributes."""

    line: int | None = field(default=None, compare=False, repr=False)
    extra_attrs: dict[str, str] = field(default_factory=dict)


# --- data -------------------------------------------------------------------------------


@dataclass(kw_only=True)
class Data(Node):
    """``<data>``: a datamodel variable with at most one of ``src``, ``expr`` or inline content."""

    id: str
    src: str | None = None
    expr: str | None = None
    text: str | None = None
    markup: str | None = None


@dataclass(kw_only=True)
class Param(Node):
    """``<param>``: a name with a value from ``expr`` or ``location``."""

    name: str
    expr: str | None = None
    location: str | None = None


@dataclass(kw_only=True)
class Content(Node):
    """``<content>``: a value from ``expr``, inline text, inline markup or an inline child chart."""

    expr: str | None = None
    text: str | None = None
    markup: str | None = None
    chart: Chart | None = None


@dataclass(kw_only=True)
class DoneData(Node):
    """``<donedata>`` of a final state: a content or params."""

    content: Content | None = None
    params: list[Param] = field(default_factory=list)


# --- executable content ------------------------------------------------------------------


@dataclass(kw_only=True)
class Raise(Node):
    """``<raise>``: put an event on the internal queue."""

    event: str


@dataclass(kw_only=True)
class Send(Node):
    """``<send>``: send an event, possibly delayed, possibly to an external I/O processor."""

    event: str | None = None
    eventexpr: str | None = None
    target: str | None = None
    targetexpr: str | None = None
    type: str | None = None
    typeexpr: str | None = None
    id: str | None = None
    idlocation: str | None = None
    delay: str | None = None
    delayexpr: str | None = None
    namelist: list[str] = field(default_factory=list)
    params: list[Param] = field(default_factory=list)
    content: Content | None = None


@dataclass(kw_only=True)
class Assign(Node):
    """``<assign>``: set a location from ``expr`` or inline content."""

    location: str
    expr: str | None = None
    text: str | None = None
    markup: str | None = None


@dataclass(kw_only=True)
class Log(Node):
    """``<log>``: report a label and a value."""

    label: str | None = None
    expr: str | None = None


@dataclass(kw_only=True)
class ElseIf(Node):
    """An ``<elseif>`` branch of an :class:`If` with the actions that follow it."""

    cond: str
    actions: list[Executable] = field(default_factory=list)


@dataclass(kw_only=True)
class Else(Node):
    """The ``<else>`` branch of an :class:`If` with the actions that follow it."""

    actions: list[Executable] = field(default_factory=list)


@dataclass(kw_only=True)
class If(Node):
    """``<if>``: the first branch whose condition holds runs."""

    cond: str
    actions: list[Executable] = field(default_factory=list)
    elseifs: list[ElseIf] = field(default_factory=list)
    orelse: Else | None = None


@dataclass(kw_only=True)
class Foreach(Node):
    """``<foreach>``: run the actions once per item of ``array``."""

    array: str
    item: str
    index: str | None = None
    actions: list[Executable] = field(default_factory=list)


@dataclass(kw_only=True)
class Script(Node):
    """``<script>``: code in the datamodel's language (refused unless the interpreter is trusted)."""

    src: str | None = None
    text: str | None = None


@dataclass(kw_only=True)
class Cancel(Node):
    """``<cancel>``: cancel a delayed send by id."""

    sendid: str | None = None
    sendidexpr: str | None = None


Executable: TypeAlias = "Raise | Send | Assign | Log | If | Foreach | Script | Cancel"
"""One element of executable content."""


@dataclass(kw_only=True)
class OnEntry(Node):
    """One ``<onentry>`` block (a state may have several; each runs on its own)."""

    actions: list[Executable] = field(default_factory=list)


@dataclass(kw_only=True)
class OnExit(Node):
    """One ``<onexit>`` block."""

    actions: list[Executable] = field(default_factory=list)


@dataclass(kw_only=True)
class Finalize(Node):
    """``<finalize>`` of an invoke: runs on each event the invoked session returns."""

    actions: list[Executable] = field(default_factory=list)


# --- structure --------------------------------------------------------------------------


@dataclass(kw_only=True)
class Transition(Node):
    """``<transition>``: ``event`` keeps the space-separated descriptors as written."""

    event: str | None = None
    cond: str | None = None
    targets: list[str] = field(default_factory=list)
    type: str = "external"
    actions: list[Executable] = field(default_factory=list)

    @property
    def events(self) -> list[str]:
        """The event descriptors, split."""
        return self.event.split() if self.event else []


@dataclass(kw_only=True)
class Invoke(Node):
    """``<invoke>``: start an external service (here: a child SCXML session) while the state is active."""

    type: str | None = None
    typeexpr: str | None = None
    src: str | None = None
    srcexpr: str | None = None
    id: str | None = None
    idlocation: str | None = None
    namelist: list[str] = field(default_factory=list)
    autoforward: bool = False
    params: list[Param] = field(default_factory=list)
    content: Content | None = None
    finalize: Finalize | None = None


@dataclass(kw_only=True)
class Initial(Node):
    """``<initial>``: the default entry of a compound state, as a transition."""

    transition: Transition


@dataclass(kw_only=True)
class History(Node):
    """``<history>``: a pseudo-state remembering a shallow or deep configuration."""

    id: str | None = None
    type: str = "shallow"
    transition: Transition | None = None


@dataclass(kw_only=True)
class Final(Node):
    """``<final>``: a final state, with optional done data."""

    id: str | None = None
    onentry: list[OnEntry] = field(default_factory=list)
    onexit: list[OnExit] = field(default_factory=list)
    donedata: DoneData | None = None


@dataclass(kw_only=True)
class State(Node):
    """``<state>``: atomic when it has no child states, compound otherwise."""

    id: str | None = None
    initial: list[str] = field(default_factory=list)
    initial_element: Initial | None = None
    data: list[Data] = field(default_factory=list)
    onentry: list[OnEntry] = field(default_factory=list)
    onexit: list[OnExit] = field(default_factory=list)
    transitions: list[Transition] = field(default_factory=list)
    invokes: list[Invoke] = field(default_factory=list)
    children: list[StateNode] = field(default_factory=list)

    @property
    def is_atomic(self) -> bool:
        """True when the state has no child states (history children do not count)."""
        return not any(not isinstance(c, History) for c in self.children)


@dataclass(kw_only=True)
class Parallel(Node):
    """``<parallel>``: all child states are active together."""

    id: str | None = None
    data: list[Data] = field(default_factory=list)
    onentry: list[OnEntry] = field(default_factory=list)
    onexit: list[OnExit] = field(default_factory=list)
    transitions: list[Transition] = field(default_factory=list)
    invokes: list[Invoke] = field(default_factory=list)
    children: list[StateNode] = field(default_factory=list)


StateNode: TypeAlias = "State | Parallel | Final | History"
"""Anything that can be a child state."""


@dataclass(kw_only=True)
class Chart(Node):
    """``<scxml>``: the document. ``namespaces`` (prefix → IRI as read) only guides the writer's prefixes."""

    name: str | None = None
    initial: list[str] = field(default_factory=list)
    datamodel: str | None = None
    binding: str | None = None
    version: str = "1.0"
    data: list[Data] = field(default_factory=list)
    scripts: list[Script] = field(default_factory=list)
    children: list[StateNode] = field(default_factory=list)
    namespaces: dict[str, str] = field(default_factory=dict, compare=False, repr=False)

    def states(self, *, include_history: bool = True) -> Iterator[StateNode]:
        """Every state of the chart in document order (pre-order), not descending into invoked charts."""
        return iter_states(self, include_history=include_history)

    def find(self, state_id: str) -> StateNode | None:
        """The state with this id, or None."""
        for node in self.states():
            if node.id == state_id:
                return node
        return None

    def parent_of(self, node: StateNode) -> State | Parallel | Chart | None:
        """The state (or the chart itself) whose child ``node`` is; None when ``node`` is not in the chart."""
        stack: list[Chart | State | Parallel] = [self]
        while stack:
            container = stack.pop()
            for child in container.children:
                if child is node:
                    return container
                if isinstance(child, State | Parallel):
                    stack.append(child)
        return None


def iter_states(container: Chart | State | Parallel, *, include_history: bool = True) -> Iterator[StateNode]:
    """The states below ``container`` in document order (pre-order)."""
    for child in container.children:
        if include_history or not isinstance(child, History):
            yield child
        if isinstance(child, State | Parallel):
            yield from iter_states(child, include_history=include_history)


def concept(state: StateNode) -> str | None:
    """The state's ``pnp:concept`` annotation as written (a local name or an IRI), or None."""
    return state.extra_attrs.get(CONCEPT)


def walk(node: Node, *, into_charts: bool = True) -> Iterator[Node]:
    """Every node reachable from ``node`` (itself included), depth first, in field order.

    Descends into inline child charts of ``<content>`` unless ``into_charts`` is False
    (the content node itself is still yielded).
    """
    yield node
    for f in dataclasses.fields(node):
        if not into_charts and f.name == "chart" and isinstance(node, Content):
            continue
        value = getattr(node, f.name)
        if isinstance(value, Node):
            yield from walk(value, into_charts=into_charts)
        elif isinstance(value, list):
            for item in value:
                if isinstance(item, Node):
                    yield from walk(item, into_charts=into_charts)
