"""The line an axiom is written at in an RDF/XML or OWL/XML file: the line of its element.

RDF/XML writes ``A ⊑ B`` as an ``rdfs:subClassOf`` element inside A's ``owl:Class``; OWL/XML as a
``SubClassOf`` element. Either way the element's IRIs in document order (with, for RDF/XML, the
subject it belongs to first) read ``A, B`` for a subclass axiom and ``A, hasSkill, S`` for a skill
restriction, which is how the element of an axiom is recognised.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from urllib.parse import urljoin

from lxml import etree

from plugnproduce.ontology.vocabulary import PNP

_RDF = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
_RDFS = "http://www.w3.org/2000/01/rdf-schema#"
_OWL = "http://www.w3.org/2002/07/owl#"
_RDF_AXIOMS = {f"{{{_RDFS}}}subClassOf", f"{{{_OWL}}}equivalentClass"}
_OWX_AXIOMS = {f"{{{_OWL}}}SubClassOf", f"{{{_OWL}}}EquivalentClasses"}


class _Iris:
    """Resolves the IRIs an element names, against its xml:base (or the file) and OWL/XML prefixes."""

    def __init__(self, tree: etree._ElementTree, path: Path):
        self.file = path.resolve().as_uri()
        root = tree.getroot()
        self.prefixes = {p.get("name", ""): p.get("IRI", "") for p in root.iter(f"{{{_OWL}}}Prefix")}
        self.ontology = root.get("ontologyIRI") or ""

    def resolve(self, el: etree._Element, value: str) -> str:
        base = el.base or self.ontology or self.file
        return urljoin(base, value)

    def named(self, el: etree._Element) -> Iterator[str]:
        """The IRIs ``el`` itself names (an attribute: rdf:about, rdf:resource, rdf:ID, IRI, abbreviatedIRI)."""
        for attr in (f"{{{_RDF}}}about", f"{{{_RDF}}}resource", "IRI"):
            if el.get(attr) is not None:
                yield self.resolve(el, el.get(attr, ""))
        if el.get(f"{{{_RDF}}}ID") is not None:
            yield self.resolve(el, "#" + el.get(f"{{{_RDF}}}ID", ""))
        short = el.get("abbreviatedIRI")
        if short is not None and ":" in short:
            prefix, local = short.split(":", 1)
            yield self.prefixes.get(prefix, prefix + ":") + local

    def subtree(self, el: etree._Element) -> list[str]:
        return [iri for e in el.iter() if isinstance(e.tag, str) for iri in self.named(e)]


def axiom_line(tree: etree._ElementTree, path: Path, kind: str, sub: str, sup: str) -> int | None:
    """The line of the element stating ``sub ⊑ sup`` (``subclass``), ``sub ≡ sup`` (``equivalent``),
    ``sub ⊑ ∃hasSkill.sup`` (``has_skill``), ``sub ⊑ ∃p.sup`` (``some``) or a definition of ``sub`` naming ``sup``
    (``defined``); else the line declaring ``sub``; else None."""
    iris = _Iris(tree, path)
    for el, named in _axiom_elements(tree, iris):
        if _matches(kind, named, sub, sup):
            return int(el.sourceline) if el.sourceline else None
    for el in tree.getroot().iter():
        if isinstance(el.tag, str) and sub in iris.named(el):
            return int(el.sourceline) if el.sourceline else None
    return None


def _axiom_elements(tree: etree._ElementTree, iris: _Iris) -> Iterator[tuple[etree._Element, list[str]]]:
    for el in tree.getroot().iter():
        if el.tag in _RDF_AXIOMS:
            parent = el.getparent()
            subject = list(iris.named(parent))[:1] if parent is not None else []
            yield el, subject + iris.subtree(el)
        elif el.tag in _OWX_AXIOMS:
            yield el, iris.subtree(el)


def _matches(kind: str, named: list[str], sub: str, sup: str) -> bool:
    if kind == "subclass":
        return named == [sub, sup]
    if kind == "equivalent":
        return len(named) == 2 and set(named) == {sub, sup}
    if kind == "defined":
        return len(named) > 2 and named[0] == sub and sup in named[1:]
    if kind == "some":
        return len(named) == 3 and named[0] == sub and named[2] == sup
    return bool(named) and named[0] == sub and str(PNP.hasSkill) in named and sup in named[1:]
