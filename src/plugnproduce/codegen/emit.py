"""Building and writing SCXML elements: namespaces, attribute names, deterministic bytes."""

from __future__ import annotations

from lxml import etree

from plugnproduce.ontology.vocabulary import PNP_IRI

SCXML_NS = "http://www.w3.org/2005/07/scxml"
NSMAP = {None: SCXML_NS, "pnp": PNP_IRI}


def el(tag: str, **attrs: str) -> etree._Element:
    """An SCXML element with the project's namespace prefixes."""
    e = etree.Element(f"{{{SCXML_NS}}}{tag}", nsmap=NSMAP)
    for k, v in attrs.items():
        e.set(k, v)
    return e


def pnp_attr(name: str) -> str:
    """The Clark name of an annotation attribute in the ontology namespace."""
    return f"{{{PNP_IRI}}}{name}"


def to_bytes(root: etree._Element) -> bytes:
    """The document as pretty-printed UTF-8 with an XML declaration; same tree, same bytes."""
    etree.cleanup_namespaces(root, top_nsmap=NSMAP)
    etree.indent(root, space="  ")
    data: bytes = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
    return data
