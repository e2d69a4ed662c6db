"""Reading SCXML executable content (``<raise>``, ``<send>``, ``<assign>``, ``<log>``, ``<if>``,
``<foreach>``, ``<script>``, ``<cancel>``) and the ``<param>`` and ``<content>`` they and ``<invoke>``
carry: one parser function per element."""

from __future__ import annotations

from collections.abc import Callable

from lxml import etree

from plugnproduce.statechart.io.elements import NS, ElementReader, element_name
from plugnproduce.statechart.model import (
    Assign,
    Cancel,
    Chart,
    Content,
    Else,
    ElseIf,
    Executable,
    Foreach,
    If,
    Log,
    Param,
    Raise,
    Script,
    Send,
)


class ActionReader(ElementReader):
    """The parser functions of executable content."""

    def scxml(self, el: etree._Element) -> Chart:
        """A whole chart (inline ``<content>`` may hold one): the document reader's."""
        raise NotImplementedError

    def actions(self, el: etree._Element) -> list[Executable]:
        """The executable content inside ``el``."""
        out: list[Executable] = []
        for child in self.children(el):
            parser = ACTION_PARSERS.get(element_name(child))
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
            tag = element_name(child)
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
            tag = element_name(child)
            if tag == "elseif" and node.orelse is None:
                self.no_children(child)
                branch = ElseIf(**self.attrs(child, ("cond",), ("cond",)))
                node.elseifs.append(branch)
                actions = branch.actions
            elif tag == "else" and node.orelse is None:
                self.no_children(child)
                node.orelse = Else(**self.attrs(child, ()))
                actions = node.orelse.actions
            elif tag in ACTION_PARSERS:
                actions.append(ACTION_PARSERS[tag](self, child))
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

    def param(self, el: etree._Element) -> Param:
        self.exclusive(el, "expr", "location")
        self.no_children(el)
        return Param(**self.attrs(el, ("name", "expr", "location"), ("name",)))

    def content(self, el: etree._Element) -> Content:
        a = self.attrs(el, ("expr",))
        kids = [c for c in el if isinstance(c.tag, str)]
        if len(kids) == 1 and kids[0].tag == NS + "scxml":
            return Content(chart=self.scxml(kids[0]), **a)
        text, markup = self.inline(el)
        if "expr" in a and (markup is not None or (text or "").strip()):
            raise self.error("<content> has both 'expr' and inline content; expected one of them", el)
        return Content(text=text, markup=markup, **a)


ACTION_PARSERS: dict[str, Callable[[ActionReader, etree._Element], Executable]] = {
    "raise": ActionReader.raise_,
    "send": ActionReader.send,
    "assign": ActionReader.assign,
    "log": ActionReader.log,
    "if": ActionReader.if_,
    "foreach": ActionReader.foreach,
    "script": ActionReader.script,
    "cancel": ActionReader.cancel,
}
