"""Write the neutral model back to W3C SCXML 1.0: deterministic and pretty-printed.

The same :class:`~plugnproduce.statechart.model.Chart` always gives the same bytes:
UTF-8 with an XML declaration, two-space indentation, SCXML attributes in a fixed
order followed by foreign attributes sorted by name, and stable namespace prefixes
(``pnp`` for the ontology, ``conf`` for the W3C conformance namespace, otherwise the
prefix the chart was read with, otherwise ``ns0``, ``ns1``, ...). Children are written
in a fixed order per element (data, entry and exit handlers, initial, transitions,
invokes, child states), which keeps every order the semantics depend on. Comments are
not kept.
"""

from __future__ import annotations

import re
from xml.sax.saxutils import escape

from lxml import etree

from plugnproduce.statechart.model import (
    PNP_NS,
    SCXML_NS,
    Assign,
    Cancel,
    Chart,
    Content,
    Data,
    DoneData,
    Executable,
    Final,
    Foreach,
    History,
    If,
    Invoke,
    Log,
    Node,
    Parallel,
    Param,
    Raise,
    Script,
    Send,
    State,
    StateNode,
    Transition,
    walk,
)

_NS = "{" + SCXML_NS + "}"
_XML_NS = "http://www.w3.org/XML/1998/namespace"
KNOWN_PREFIXES = {PNP_NS: "pnp", "http://www.w3.org/2005/scxml-conformance": "conf"}
"""Namespaces that always get the same prefix."""


def write_chart(chart: Chart) -> bytes:
    """The chart as SCXML bytes (UTF-8, XML declaration, 2-space indentation, trailing newline)."""
    writer = _Writer()
    root = writer.scxml(chart, etree.Element(_NS + "scxml", nsmap=_nsmap(chart)))
    etree.indent(root, space="  ")
    body: bytes = etree.tostring(root, encoding="UTF-8")
    data = b'<?xml version="1.0" encoding="UTF-8"?>\n' + body + b"\n"
    for token, markup in writer.markup.items():
        data = data.replace(token.encode(), _standalone_markup(markup).encode(), 1)
    return data


def _standalone_markup(markup: str) -> str:
    """Inline markup as read, with ``xmlns=""`` on top elements in no namespace (they sit in SCXML's)."""
    wrapper = etree.fromstring(f"<w>{markup}</w>".encode(), parser=_MARKUP_PARSER)
    parts = [escape(wrapper.text or "")]
    for child in wrapper:
        if isinstance(child.tag, str):
            text = etree.tostring(child, method="c14n", exclusive=True, with_tail=False).decode()
            if not child.tag.startswith("{"):
                text = re.sub(r"^<([^\s/>]+)", r'<\1 xmlns=""', text, count=1)
            parts.append(text)
        parts.append(escape(child.tail or ""))
    return "".join(parts)


def _nsmap(chart: Chart) -> dict[str | None, str]:
    """Prefix → namespace for every foreign namespace the chart's annotations use."""
    used = sorted({key[1:].split("}")[0] for node in walk(chart) for key in node.extra_attrs} - {_XML_NS})
    nsmap: dict[str | None, str] = {None: SCXML_NS}
    taken = set(KNOWN_PREFIXES.values())
    read_with = {uri: prefix for prefix, uri in sorted(chart.namespaces.items())}
    counter = 0
    for uri in used:
        prefix = KNOWN_PREFIXES.get(uri)
        if prefix is None and read_with.get(uri) not in taken | {None, "xml"}:
            prefix = read_with[uri]
        while prefix is None:
            candidate = f"ns{counter}"
            counter += 1
            prefix = candidate if candidate not in taken | set(read_with.values()) else None
        taken.add(prefix)
        nsmap[prefix] = uri
    return nsmap


_MARKUP_PARSER = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)


class _Writer:
    """One writer function per element."""

    def __init__(self) -> None:
        self.markup: dict[str, str] = {}

    def element(self, parent: etree._Element, tag: str, node: Node, attrs: dict[str, str | None]) -> etree._Element:
        el = etree.SubElement(parent, _NS + tag)
        self.set_attrs(el, node, attrs)
        return el

    @staticmethod
    def set_attrs(el: etree._Element, node: Node, attrs: dict[str, str | None]) -> None:
        for key, value in attrs.items():
            if value is not None:
                el.set(key, value)
        for key in sorted(node.extra_attrs):
            el.set(key, node.extra_attrs[key])

    def inline(self, el: etree._Element, text: str | None, markup: str | None) -> None:
        """Inline text as is; inline markup as a placeholder replaced after serialisation (written as read)."""
        if markup is not None:
            token = f"\ue000markup{len(self.markup)}\ue000"
            self.markup[token] = markup
            el.text = token
        elif text is not None:
            el.text = text

    # --- document and states ---------------------------------------------------------

    def scxml(self, chart: Chart, el: etree._Element) -> etree._Element:
        self.set_attrs(el, chart, {"version": chart.version, "name": chart.name,
                                   "initial": _join(chart.initial), "datamodel": chart.datamodel,
                                   "binding": chart.binding})
        self.datamodel(el, chart.data)
        for script in chart.scripts:
            self.script(el, script)
        self.states(el, chart.children)
        return el

    def states(self, parent: etree._Element, children: list[StateNode]) -> None:
        for child in children:
            if isinstance(child, State):
                self.state(parent, child)
            elif isinstance(child, Parallel):
                self.parallel(parent, child)
            elif isinstance(child, Final):
                self.final(parent, child)
            else:
                self.history(parent, child)

    def state(self, parent: etree._Element, state: State) -> None:
        el = self.element(parent, "state", state, {"id": state.id, "initial": _join(state.initial)})
        self.datamodel(el, state.data)
        self.handlers(el, state)
        if state.initial_element is not None:
            initial = self.element(el, "initial", state.initial_element, {})
            self.transition(initial, state.initial_element.transition)
        self.body(el, state)

    def parallel(self, parent: etree._Element, par: Parallel) -> None:
        el = self.element(parent, "parallel", par, {"id": par.id})
        self.datamodel(el, par.data)
        self.handlers(el, par)
        self.body(el, par)

    def handlers(self, el: etree._Element, state: State | Parallel | Final) -> None:
        for block in state.onentry:
            self.actions(self.element(el, "onentry", block, {}), block.actions)
        for exit_block in state.onexit:
            self.actions(self.element(el, "onexit", exit_block, {}), exit_block.actions)

    def body(self, el: etree._Element, state: State | Parallel) -> None:
        for t in state.transitions:
            self.transition(el, t)
        for invoke in state.invokes:
            self.invoke(el, invoke)
        self.states(el, state.children)

    def final(self, parent: etree._Element, final: Final) -> None:
        el = self.element(parent, "final", final, {"id": final.id})
        self.handlers(el, final)
        if final.donedata is not None:
            self.donedata(el, final.donedata)

    def history(self, parent: etree._Element, history: History) -> None:
        kind = None if history.type == "shallow" else history.type
        el = self.element(parent, "history", history, {"id": history.id, "type": kind})
        if history.transition is not None:
            self.transition(el, history.transition)

    def transition(self, parent: etree._Element, t: Transition) -> None:
        kind = None if t.type == "external" else t.type
        el = self.element(parent, "transition", t, {"event": t.event, "cond": t.cond,
                                                    "target": _join(t.targets), "type": kind})
        self.actions(el, t.actions)

    # --- data ------------------------------------------------------------------------

    def datamodel(self, parent: etree._Element, data: list[Data]) -> None:
        if not data:
            return
        el = etree.SubElement(parent, _NS + "datamodel")
        for d in data:
            self.inline(self.element(el, "data", d, {"id": d.id, "src": d.src, "expr": d.expr}), d.text, d.markup)

    def param(self, parent: etree._Element, p: Param) -> None:
        self.element(parent, "param", p, {"name": p.name, "expr": p.expr, "location": p.location})

    def content(self, parent: etree._Element, c: Content) -> None:
        el = self.element(parent, "content", c, {"expr": c.expr})
        if c.chart is not None:
            self.scxml(c.chart, etree.SubElement(el, _NS + "scxml"))
        else:
            self.inline(el, c.text, c.markup)

    def donedata(self, parent: etree._Element, done: DoneData) -> None:
        el = self.element(parent, "donedata", done, {})
        if done.content is not None:
            self.content(el, done.content)
        for p in done.params:
            self.param(el, p)

    def invoke(self, parent: etree._Element, inv: Invoke) -> None:
        el = self.element(parent, "invoke", inv, {
            "type": inv.type, "typeexpr": inv.typeexpr, "src": inv.src, "srcexpr": inv.srcexpr, "id": inv.id,
            "idlocation": inv.idlocation, "namelist": _join(inv.namelist),
            "autoforward": "true" if inv.autoforward else None})
        for p in inv.params:
            self.param(el, p)
        if inv.content is not None:
            self.content(el, inv.content)
        if inv.finalize is not None:
            self.actions(self.element(el, "finalize", inv.finalize, {}), inv.finalize.actions)

    # --- executable content ----------------------------------------------------------

    def actions(self, parent: etree._Element, actions: list[Executable]) -> None:
        for action in actions:
            self.action(parent, action)

    def action(self, parent: etree._Element, a: Executable) -> None:  # noqa: C901 - one branch per element
        if isinstance(a, Raise):
            self.element(parent, "raise", a, {"event": a.event})
        elif isinstance(a, Send):
            self.send(parent, a)
        elif isinstance(a, Assign):
            el = self.element(parent, "assign", a, {"location": a.location, "expr": a.expr})
            self.inline(el, a.text, a.markup)
        elif isinstance(a, Log):
            self.element(parent, "log", a, {"label": a.label, "expr": a.expr})
        elif isinstance(a, If):
            self.if_(parent, a)
        elif isinstance(a, Foreach):
            el = self.element(parent, "foreach", a, {"array": a.array, "item": a.item, "index": a.index})
            self.actions(el, a.actions)
        elif isinstance(a, Script):
            self.script(parent, a)
        elif isinstance(a, Cancel):
            self.element(parent, "cancel", a, {"sendid": a.sendid, "sendidexpr": a.sendidexpr})
        else:
            raise TypeError(f"not executable content: {a!r}")

    def send(self, parent: etree._Element, s: Send) -> None:
        el = self.element(parent, "send", s, {
            "event": s.event, "eventexpr": s.eventexpr, "target": s.target, "targetexpr": s.targetexpr,
            "type": s.type, "typeexpr": s.typeexpr, "id": s.id, "idlocation": s.idlocation, "delay": s.delay,
            "delayexpr": s.delayexpr, "namelist": _join(s.namelist)})
        for p in s.params:
            self.param(el, p)
        if s.content is not None:
            self.content(el, s.content)

    def if_(self, parent: etree._Element, node: If) -> None:
        el = self.element(parent, "if", node, {"cond": node.cond})
        self.actions(el, node.actions)
        for branch in node.elseifs:
            self.element(el, "elseif", branch, {"cond": branch.cond})
            self.actions(el, branch.actions)
        if node.orelse is not None:
            self.element(el, "else", node.orelse, {})
            self.actions(el, node.orelse.actions)

    def script(self, parent: etree._Element, s: Script) -> None:
        el = self.element(parent, "script", s, {"src": s.src})
        if s.text is not None:
            el.text = s.text


def _join(values: list[str]) -> str | None:
    return " ".join(values) if values else None
