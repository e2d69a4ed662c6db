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

from lxml import etree

from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.safeio import parse_xml_bytes, read_bytes
from plugnproduce.statechart.io.actions import ActionReader
from plugnproduce.statechart.io.checks import check_structure
from plugnproduce.statechart.io.elements import NS, element_name
from plugnproduce.statechart.model import (
    SCXML_NS,
    Chart,
    Data,
    DoneData,
    Final,
    Finalize,
    History,
    Initial,
    Invoke,
    OnEntry,
    OnExit,
    Parallel,
    State,
    StateNode,
    Transition,
)


def read_chart(path: str | Path) -> Chart:
    """Read an SCXML file into a :class:`Chart` (hardened: size, DOCTYPE and depth are checked)."""
    return parse_chart(read_bytes(path), path)


def parse_chart(data: bytes, source: str | Path) -> Chart:
    """Parse SCXML bytes into a :class:`Chart`; ``source`` names the document in errors."""
    root = parse_xml_bytes(data, source).getroot()
    reader = _Reader(str(source))
    if root.tag != NS + "scxml":
        raise DescriptionError(f"found <{excerpt(element_name(root))}> at the top; expected <scxml> in the namespace "
                               f"{SCXML_NS}", source, root.sourceline)
    chart = reader.scxml(root)
    check_structure(chart, str(source))
    return chart


class _Reader(ActionReader):
    """The parser functions of the document, its states and their data, one per element."""

    # --- document and states ---------------------------------------------------------

    def scxml(self, el: etree._Element) -> Chart:
        a = self.attrs(el, ("initial", "name", "version", "datamodel", "binding"))
        a["initial"] = a.get("initial", "").split()
        chart = Chart(**a)
        chart.namespaces = {p: u for p, u in el.nsmap.items() if p is not None and u != SCXML_NS}
        for child in self.children(el):
            tag = element_name(child)
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
            tag = element_name(child)
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
            tag = element_name(child)
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
            tag = element_name(child)
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
            if element_name(child) != "transition" or history.transition is not None:
                raise self.unexpected(child, el, "one <transition>")
            history.transition = self.transition(child)
        return history

    def initial(self, el: etree._Element) -> Initial:
        a = self.attrs(el, ())
        kids = self.children(el)
        if len(kids) != 1 or element_name(kids[0]) != "transition":
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
            if element_name(child) != "data":
                raise self.unexpected(child, el, "<data>")
            out.append(self.data(child))
        return out

    def data(self, el: etree._Element) -> Data:
        self.exclusive(el, "src", "expr")
        text, markup = self.inline(el)
        if (el.get("src") or el.get("expr")) is not None and (markup is not None or (text or "").strip()):
            raise self.error("<data> has both an attribute value and inline content; expected one of them", el)
        return Data(text=text, markup=markup, **self.attrs(el, ("id", "src", "expr"), ("id",)))

    def donedata(self, el: etree._Element) -> DoneData:
        done = DoneData(**self.attrs(el, ()))
        for child in self.children(el):
            tag = element_name(child)
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
            tag = element_name(child)
            if tag == "param":
                invoke.params.append(self.param(child))
            elif tag == "content" and invoke.content is None:
                invoke.content = self.content(child)
            elif tag == "finalize" and invoke.finalize is None:
                invoke.finalize = self.finalize(child)
            else:
                raise self.unexpected(child, el, "<param>, one <content> or one <finalize>")
        return invoke

_STATE_PARSERS: dict[str, Callable[[_Reader, etree._Element], StateNode]] = {
    "state": _Reader.state,
    "parallel": _Reader.parallel,
    "final": _Reader.final,
    "history": _Reader.history,
}
