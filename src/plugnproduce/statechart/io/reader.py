"""Read W3C SCXML 1.0 into the neutral model (:mod:`plugnproduce.statechart.model`).

Parsing goes through the hardened parser (:func:`plugnproduce.safeio.parse_xml_bytes`).
There is one parser function per SCXML element. An unknown element or attribute in the
SCXML namespace, a misplaced element or a broken reference (a transition target or
an initial state that does not exist, a duplicate id) is a
:class:`~plugnproduce.errors.DescriptionError` with the file and line. Attributes in
other namespaces are kept in ``extra_attrs``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape

from lxml import etree

from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.safeio import parse_xml_bytes, read_bytes
from plugnproduce.statechart.io.checks import check_structure
from plugnproduce.statechart.model import (
    SCXML_NS,
    Assign,
    Cancel,
    Chart,
    Content,
    Data,
    DoneData,
    Else,
    ElseIf,
    Executable,
    Final,
    Finalize,
    Foreach,
    History,
    If,
    Initial,
    Invoke,
    Log,
    OnEntry,
    OnExit,
    Parallel,
    Param,
    Raise,
    Script,
    Send,
    State,
    StateNode,
    Transition,
)

_NS = "{" + SCXML_NS + "}"
_SPEC = "https://www.w3.org/TR/scxml/"


def read_chart(path: str | Path) -> Chart:
    """Read an SCXML file into a :class:`Chart` (hardened: size, DOCTYPE and depth are checked)."""
    return parse_chart(read_bytes(path), path)


def parse_chart(data: bytes, source: str | Path) -> Chart:
    """Parse SCXML bytes into a :class:`Chart`; ``source`` names the document in errors."""
    root = parse_xml_bytes(data, source).getroot()
    reader = _Reader(str(source))
    if root.tag != _NS + "scxml":
        raise DescriptionError(f"found <{excerpt(_name(root))}> at the top; expected <scxml> in the namespace "
                               f"{SCXML_NS}", source, root.sourceline)
    chart = reader.scxml(root)
    check_structure(chart, str(source))
    return chart


def _name(el: etree._Element) -> str:
    """An element's tag as a reader would write it: local name in SCXML, Clark notation otherwise."""
    tag = str(el.tag)
    return tag[len(_NS):] if tag.startswith(_NS) else tag


class _Reader:
    """The parser functions, one per element, sharing the source name for errors."""

    def __init__(self, source: str):
        self.source = source

    # --- helpers ---------------------------------------------------------------------

    def error(self, message: str, el: etree._Element) -> DescriptionError:
        return DescriptionError(message, self.source, el.sourceline)

    def attrs(self, el: etree._Element, allowed: tuple[str, ...], required: tuple[str, ...] = ()) -> dict[str, Any]:
        """Known attributes (unqualified) and ``extra_attrs`` (foreign namespaces) of ``el``."""
        known: dict[str, Any] = {"line": el.sourceline, "extra_attrs": {}}
        for key, value in el.attrib.items():
            key = str(key)
            if key.startswith("{"):
                if key.startswith(_NS):
                    raise self.error(f"attribute {key[len(_NS):]!r} in the SCXML namespace on <{_name(el)}>; "
                                     "expected SCXML attributes without a prefix", el)
                known["extra_attrs"][key] = str(value)
            elif key in allowed:
                known[key] = str(value)
            else:
                raise self.error(f"unknown attribute {key!r} on <{_name(el)}>; expected one of "
                                 f"{', '.join(allowed) or 'none'} ({_SPEC})", el)
        for key in required:
            if key not in known:
                raise self.error(f"<{_name(el)}> lacks the required attribute {key!r}", el)
        return known

    def exclusive(self, el: etree._Element, *names: str) -> None:
        """Refuse an element that gives more than one of ``names`` (the spec allows only one)."""
        given = [n for n in names if el.get(n) is not None]
        if len(given) > 1:
            raise self.error(f"<{_name(el)}> has both {given[0]!r} and {given[1]!r}; expected at most one of "
                             f"{', '.join(names)}", el)

    def children(self, el: etree._Element) -> list[etree._Element]:
        """Element children (comments and processing instructions skipped); foreign elements refused."""
        out = []
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if not child.tag.startswith(_NS):
                raise self.error(f"found the foreign element <{child.tag}> in <{_name(el)}>; "
                                 "expected only SCXML elements (foreign attributes are kept, elements are not)", child)
            out.append(child)
        return out

    def unexpected(self, child: etree._Element, parent: etree._Element, expected: str) -> DescriptionError:
        return self.error(f"found <{_name(child)}> in <{_name(parent)}>; expected {expected}", child)

    def inline(self, el: etree._Element) -> tuple[str | None, str | None]:
        """Inline content of ``<data>``, ``<assign>`` or ``<content>``: (text, markup).

        Markup is the element's inner XML with each child in exclusive canonical form,
        so that it reads the same wherever the writer puts it back.
        """
        if not any(isinstance(c.tag, str) for c in el):
            return el.text, None
        parts = [escape(el.text or "")]
        for child in el:
            if isinstance(child.tag, str):
                parts.append(etree.tostring(child, method="c14n", exclusive=True, with_tail=False).decode())
            parts.append(escape(child.tail or ""))
        return None, "".join(parts)

    # --- document and states ---------------------------------------------------------

    def scxml(self, el: etree._Element) -> Chart:
        a = self.attrs(el, ("initial", "name", "version", "datamodel", "binding"))
        a["initial"] = a.get("initial", "").split()
        chart = Chart(**a)
        chart.namespaces = {p: u for p, u in el.nsmap.items() if p is not None and u != SCXML_NS}
        for child in self.children(el):
            tag = _name(child)
            if tag in ("state", "parallel", "final"):
                chart.children.append(_STATE_PARSERS[tag](self, child))
            elif tag == "datamodel":
                chart.data.extend(self.datamodel(child))
            elif tag == "script":
                chart.scripts.append(self.script(child))
            else:
                raise self.unexpected(child, el, "<state>, <parallel>, <final>, <datamodel> or <script>")
        return chart

    def state(self, el: etree._Element) -> State:
        a = self.attrs(el, ("id", "initial"))
        a["initial"] = a.get("initial", "").split()
        state = State(**a)
        for child in self.children(el):
            tag = _name(child)
            if tag == "initial":
                if state.initial_element is not None or state.initial:
                    raise self.error("a second initial (element or attribute); expected at most one", child)
                state.initial_element = self.initial(child)
            elif not self.state_child(state, child, tag):
                raise self.unexpected(child, el, "<onentry>, <onexit>, <transition>, <initial>, <state>, "
                                      "<parallel>, <final>, <history>, <datamodel> or <invoke>")
        return state

    def parallel(self, el: etree._Element) -> Parallel:
        par = Parallel(**self.attrs(el, ("id",)))
        for child in self.children(el):
            tag = _name(child)
            if tag == "final" or not self.state_child(par, child, tag):
                raise self.unexpected(child, el, "<onentry>, <onexit>, <transition>, <state>, <parallel>, "
                                      "<history>, <datamodel> or <invoke>")
        return par

    def state_child(self, state: State | Parallel, child: etree._Element, tag: str) -> bool:
        """Add a child common to ``<state>`` and ``<parallel>``; False when the tag is not one."""
        if tag in _STATE_PARSERS:
            state.children.append(_STATE_PARSERS[tag](self, child))
        elif tag == "onentry":
            state.onentry.append(self.onentry(child))
        elif tag == "onexit":
            state.onexit.append(self.onexit(child))
        elif tag == "transition":
            state.transitions.append(self.transition(child))
        elif tag == "datamodel":
            state.data.extend(self.datamodel(child))
        elif tag == "invoke":
            state.invokes.append(self.invoke(child))
        else:
            return False
        return True

    def final(self, el: etree._Element) -> Final:
        final = Final(**self.attrs(el, ("id",)))
        for child in self.children(el):
            tag = _name(child)
            if tag == "onentry":
                final.onentry.append(self.onentry(child))
            elif tag == "onexit":
                final.onexit.append(self.onexit(child))
            elif tag == "donedata" and final.donedata is None:
                final.donedata = self.donedata(child)
            else:
                raise self.unexpected(child, el, "<onentry>, <onexit> or one <donedata>")
        return final

    def history(self, el: etree._Element) -> History:
        a = self.attrs(el, ("id", "type"))
        if a.get("type", "shallow") not in ("shallow", "deep"):
            raise self.error(f"history type {a['type']!r}; expected 'shallow' or 'deep'", el)
        history = History(**a)
        for child in self.children(el):
            if _name(child) != "transition" or history.transition is not None:
                raise self.unexpected(child, el, "one <transition>")
            history.transition = self.transition(child)
        return history

    def initial(self, el: etree._Element) -> Initial:
        a = self.attrs(el, ())
        kids = self.children(el)
        if len(kids) != 1 or _name(kids[0]) != "transition":
            raise self.error(f"<initial> holds {len(kids)} elements; expected exactly one <transition>", el)
        return Initial(transition=self.transition(kids[0]), **a)

    def transition(self, el: etree._Element) -> Transition:
        a = self.attrs(el, ("event", "cond", "target", "type"))
        a["targets"] = a.pop("target", "").split()
        if a.get("type", "external") not in ("external", "internal"):
            raise self.error(f"transition type {a['type']!r}; expected 'external' or 'internal'", el)
        return Transition(actions=self.actions(el), **a)

    def onentry(self, el: etree._Element) -> OnEntry:
        return OnEntry(actions=self.actions(el), **self.attrs(el, ()))

    def onexit(self, el: etree._Element) -> OnExit:
        return OnExit(actions=self.actions(el), **self.attrs(el, ()))

    def finalize(self, el: etree._Element) -> Finalize:
        return Finalize(actions=self.actions(el), **self.attrs(el, ()))

    # --- data ------------------------------------------------------------------------

    def datamodel(self, el: etree._Element) -> list[Data]:
        self.attrs(el, ())
        out = []
        for child in self.children(el):
            if _name(child) != "data":
                raise self.unexpected(child, el, "<data>")
            out.append(self.data(child))
        return out

    def data(self, el: etree._Element) -> Data:
        self.exclusive(el, "src", "expr")
        text, markup = self.inline(el)
        if (el.get("src") or el.get("expr")) is not None and (markup is not None or (text or "").strip()):
            raise self.error("<data> has both an attribute value and inline content; expected one of them", el)
        return Data(text=text, markup=markup, **self.attrs(el, ("id", "src", "expr"), ("id",)))

    def param(self, el: etree._Element) -> Param:
        self.exclusive(el, "expr", "location")
        self.no_children(el)
        return Param(**self.attrs(el, ("name", "expr", "location"), ("name",)))

    def content(self, el: etree._Element) -> Content:
        a = self.attrs(el, ("expr",))
        kids = [c for c in el if isinstance(c.tag, str)]
        if len(kids) == 1 and kids[0].tag == _NS + "scxml":
            return Content(chart=self.scxml(kids[0]), **a)
        text, markup = self.inline(el)
        if "expr" in a and (markup is not None or (text or "").strip()):
            raise self.error("<content> has both 'expr' and inline content; expected one of them", el)
        return Content(text=text, markup=markup, **a)

    def donedata(self, el: etree._Element) -> DoneData:
        done = DoneData(**self.attrs(el, ()))
        for child in self.children(el):
            tag = _name(child)
            if tag == "content" and done.content is None and not done.params:
                done.content = self.content(child)
            elif tag == "param" and done.content is None:
                done.params.append(self.param(child))
            else:
                raise self.unexpected(child, el, "one <content> or any number of <param>")
        return done

    def invoke(self, el: etree._Element) -> Invoke:
        for pair in (("type", "typeexpr"), ("src", "srcexpr"), ("id", "idlocation")):
            self.exclusive(el, *pair)
        a = self.attrs(el, ("type", "typeexpr", "src", "srcexpr", "id", "idlocation", "namelist", "autoforward"))
        a["namelist"] = a.get("namelist", "").split()
        if a.get("autoforward", "false") not in ("true", "false"):
            raise self.error(f"autoforward {a['autoforward']!r}; expected 'true' or 'false'", el)
        a["autoforward"] = a.get("autoforward") == "true"
        invoke = Invoke(**a)
        for child in self.children(el):
            tag = _name(child)
            if tag == "param":
                invoke.params.append(self.param(child))
            elif tag == "content" and invoke.content is None:
                invoke.content = self.content(child)
            elif tag == "finalize" and invoke.finalize is None:
                invoke.finalize = self.finalize(child)
            else:
                raise self.unexpected(child, el, "<param>, one <content> or one <finalize>")
        return invoke

    # --- executable content ----------------------------------------------------------

    def actions(self, el: etree._Element) -> list[Executable]:
        """The executable content inside ``el``."""
        out: list[Executable] = []
        for child in self.children(el):
            parser = _ACTION_PARSERS.get(_name(child))
            if parser is None:
                raise self.unexpected(child, el, "executable content (<raise>, <send>, <assign>, <log>, <if>, "
                                      "<foreach>, <script>, <cancel>)")
            out.append(parser(self, child))
        return out

    def raise_(self, el: etree._Element) -> Raise:
        self.no_children(el)
        return Raise(**self.attrs(el, ("event",), ("event",)))

    def send(self, el: etree._Element) -> Send:
        for pair in (("event", "eventexpr"), ("target", "targetexpr"), ("type", "typeexpr"),
                     ("id", "idlocation"), ("delay", "delayexpr")):
            self.exclusive(el, *pair)
        a = self.attrs(el, ("event", "eventexpr", "target", "targetexpr", "type", "typeexpr", "id",
                            "idlocation", "delay", "delayexpr", "namelist"))
        a["namelist"] = a.get("namelist", "").split()
        send = Send(**a)
        for child in self.children(el):
            tag = _name(child)
            if tag == "param" and send.content is None:
                send.params.append(self.param(child))
            elif tag == "content" and send.content is None and not send.params and not send.namelist:
                send.content = self.content(child)
            else:
                raise self.unexpected(child, el, "<param> elements or one <content> (not both, nor with namelist)")
        return send

    def assign(self, el: etree._Element) -> Assign:
        text, markup = self.inline(el)
        a = self.attrs(el, ("location", "expr"), ("location",))
        if "expr" in a and (markup is not None or (text or "").strip()):
            raise self.error("<assign> has both 'expr' and inline content; expected one of them", el)
        return Assign(text=text, markup=markup, **a)

    def log(self, el: etree._Element) -> Log:
        self.no_children(el)
        return Log(**self.attrs(el, ("label", "expr")))

    def if_(self, el: etree._Element) -> If:
        node = If(**self.attrs(el, ("cond",), ("cond",)))
        actions = node.actions
        for child in self.children(el):
            tag = _name(child)
            if tag == "elseif" and node.orelse is None:
                self.no_children(child)
                branch = ElseIf(**self.attrs(child, ("cond",), ("cond",)))
                node.elseifs.append(branch)
                actions = branch.actions
            elif tag == "else" and node.orelse is None:
                self.no_children(child)
                node.orelse = Else(**self.attrs(child, ()))
                actions = node.orelse.actions
            elif tag in _ACTION_PARSERS:
                actions.append(_ACTION_PARSERS[tag](self, child))
            else:
                raise self.unexpected(child, el, "executable content, <elseif> or one <else> (last)")
        return node

    def foreach(self, el: etree._Element) -> Foreach:
        return Foreach(actions=self.actions(el), **self.attrs(el, ("array", "item", "index"), ("array", "item")))

    def script(self, el: etree._Element) -> Script:
        self.no_children(el)
        a = self.attrs(el, ("src",))
        if "src" in a and (el.text or "").strip():
            raise self.error("<script> has both 'src' and inline code; expected one of them", el)
        return Script(text=el.text if "src" not in a else None, **a)

    def cancel(self, el: etree._Element) -> Cancel:
        self.no_children(el)
        self.exclusive(el, "sendid", "sendidexpr")
        a = self.attrs(el, ("sendid", "sendidexpr"))
        if "sendid" not in a and "sendidexpr" not in a:
            raise self.error("<cancel> lacks 'sendid' and 'sendidexpr'; expected one of them", el)
        return Cancel(**a)

    def no_children(self, el: etree._Element) -> None:
        kids = self.children(el)
        if kids:
            raise self.unexpected(kids[0], el, "no child elements")


_STATE_PARSERS: dict[str, Callable[[_Reader, etree._Element], StateNode]] = {
    "state": _Reader.state,
    "parallel": _Reader.parallel,
    "final": _Reader.final,
    "history": _Reader.history,
}

_ACTION_PARSERS: dict[str, Callable[[_Reader, etree._Element], Executable]] = {
    "raise": _Reader.raise_,
    "send": _Reader.send,
    "assign": _Reader.assign,
    "log": _Reader.log,
    "if": _Reader.if_,
    "foreach": _Reader.foreach,
    "script": _Reader.script,
    "cancel": _Reader.cancel,
}
