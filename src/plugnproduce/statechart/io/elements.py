"""Reading SCXML elements: attributes (known ones, and foreign-namespace ones kept), children and inline
content, each refusal with the file and line; the ground the reader's parser functions stand on."""

from __future__ import annotations

from typing import Any
from xml.sax.saxutils import escape

from lxml import etree

from plugnproduce.errors import DescriptionError
from plugnproduce.statechart.model import SCXML_NS

NS = "{" + SCXML_NS + "}"
"""The SCXML namespace in Clark notation, as lxml writes tags."""
SPEC = "https://www.w3.org/TR/scxml/"


def element_name(el: etree._Element) -> str:
    """An element's tag as a reader would write it: local name in SCXML, Clark notation otherwise."""
    tag = str(el.tag)
    return tag[len(NS):] if tag.startswith(NS) else tag


class ElementReader:
    """The helpers of the parser functions, sharing the source name for errors."""

    def __init__(self, source: str):
        self.source = source

    def error(self, message: str, el: etree._Element) -> DescriptionError:
        """An error at ``el``'s line."""
        return DescriptionError(message, self.source, el.sourceline)

    def attrs(self, el: etree._Element, allowed: tuple[str, ...], required: tuple[str, ...] = ()) -> dict[str, Any]:
        """Known attributes (unqualified) and ``extra_attrs`` (foreign namespaces) of ``el``."""
        known: dict[str, Any] = {"line": el.sourceline, "extra_attrs": {}}
        for key, value in el.attrib.items():
            key = str(key)
            if key.startswith("{"):
                if key.startswith(NS):
                    raise self.error(f"attribute {key[len(NS):]!r} in the SCXML namespace on <{element_name(el)}>; "
                                     "expected SCXML attributes without a prefix", el)
                known["extra_attrs"][key] = str(value)
            elif key in allowed:
                known[key] = str(value)
            else:
                raise self.error(f"unknown attribute {key!r} on <{element_name(el)}>; expected one of "
                                 f"{', '.join(allowed) or 'none'} ({SPEC})", el)
        for key in required:
            if key not in known:
                raise self.error(f"<{element_name(el)}> lacks the required attribute {key!r}", el)
        return known

    def exclusive(self, el: etree._Element, *names: str) -> None:
        """Refuse an element that gives more than one of ``names`` (the spec allows only one)."""
        given = [n for n in names if el.get(n) is not None]
        if len(given) > 1:
            raise self.error(f"<{element_name(el)}> has both {given[0]!r} and {given[1]!r}; expected at most one of "
                             f"{', '.join(names)}", el)

    def children(self, el: etree._Element) -> list[etree._Element]:
        """Element children (comments and processing instructions skipped); foreign elements refused."""
        out = []
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if not child.tag.startswith(NS):
                raise self.error(f"found the foreign element <{child.tag}> in <{element_name(el)}>; "
                                 "expected only SCXML elements (foreign attributes are kept, elements are not)", child)
            out.append(child)
        return out

    def unexpected(self, child: etree._Element, parent: etree._Element, expected: str) -> DescriptionError:
        """``child`` has no place in ``parent``, which expects ``expected``."""
        return self.error(f"found <{element_name(child)}> in <{element_name(parent)}>; expected {expected}", child)

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

    def no_children(self, el: etree._Element) -> None:
        """Refuse any child element."""
        kids = self.children(el)
        if kids:
            raise self.unexpected(kids[0], el, "no child elements")
