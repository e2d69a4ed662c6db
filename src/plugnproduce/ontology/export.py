"""The merged TBox written out for Protégé: Turtle, RDF/XML or OWL/XML, optionally with what HermiT derived.

The TBox files of the loaded libraries become one ontology (their ``owl:imports`` are merged in, so
they are dropped). With ``inferred``, every direct subclass and equivalence the reasoner derived and no
file asserts is added as an asserted axiom, annotated ``pnp:inferredBy "HermiT"`` (an OWL axiom
annotation, which Protégé shows beside the axiom). rdflib writes Turtle and RDF/XML; py-horned-owl
turns the RDF/XML into OWL/XML.
"""

from __future__ import annotations

from collections.abc import Iterator

import rdflib
from rdflib.namespace import OWL, RDF, RDFS

from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.taxonomy import Taxonomy

FORMATS = ("rdfxml", "turtle", "owlxml")
MERGED = rdflib.URIRef("http://plugnproduce.org/ontology/merged")
"""The IRI of the exported ontology."""
INFERRED_BY = rdflib.URIRef(PNP_IRI + "inferredBy")
"""The annotation property that marks an axiom the reasoner derived (its value: the reasoner)."""
REASONER = "HermiT"
_CLASS_EXPRESSIONS = (OWL.unionOf, OWL.intersectionOf, OWL.complementOf, OWL.oneOf)


def merged_tbox(tbox: rdflib.Graph, taxonomy: Taxonomy, sources: list[str], inferred: bool) -> rdflib.Graph:
    """The TBox as one ontology (``sources`` named in its comment); with ``inferred``, the derived hierarchy too."""
    g = rdflib.Graph()
    headers = set(tbox.subjects(RDF.type, OWL.Ontology))
    for s, p, o in tbox:
        if s not in headers and p != OWL.imports:
            g.add((s, p, o))
    for prefix, ns in tbox.namespaces():
        g.bind(prefix, ns, override=False)
    g.bind("pnp", PNP_IRI)
    _typed_expressions(g)
    g.add((MERGED, RDF.type, OWL.Ontology))
    g.add((MERGED, RDFS.comment, rdflib.Literal("The merged TBox of: " + ", ".join(sources))))
    if inferred:
        g.add((INFERRED_BY, RDF.type, OWL.AnnotationProperty))
        g.add((INFERRED_BY, RDFS.label, rdflib.Literal("inferred by")))
        g.add((MERGED, RDFS.comment, rdflib.Literal(
            f"Axioms annotated pnp:inferredBy \"{REASONER}\" are the hierarchy the reasoner derived; no file asserts "
            "them.")))
        for sub, prop, sup in derived_axioms(g, taxonomy):
            _annotated(g, sub, prop, sup)
    return g


def _typed_expressions(g: rdflib.Graph) -> None:
    """OWL 2's RDF mapping wants anonymous class expressions and restrictions typed; Turtle files often omit it."""
    for p in _CLASS_EXPRESSIONS:
        for s in list(g.subjects(p, None)):
            if isinstance(s, rdflib.BNode):
                g.add((s, RDF.type, OWL.Class))
    for s in list(g.subjects(OWL.onProperty, None)):
        g.add((s, RDF.type, OWL.Restriction))


def derived_axioms(g: rdflib.Graph, taxonomy: Taxonomy) -> Iterator[tuple[rdflib.URIRef, rdflib.URIRef, rdflib.URIRef]]:
    """The direct subclass and equivalence axioms between named classes that the reasoner derived and ``g``
    does not assert."""
    for c in sorted(taxonomy.superclasses):
        ups = taxonomy.superclasses[c] - {c}
        same = {s for s in ups if taxonomy.is_a(s, c)}
        strict = ups - same
        direct = {s for s in strict if not any(o != s and taxonomy.is_a(o, s) and not taxonomy.is_a(s, o)
                                               for o in strict)}
        sub = rdflib.URIRef(c)
        for s in sorted(direct):
            if (sub, RDFS.subClassOf, rdflib.URIRef(s)) not in g:
                yield sub, RDFS.subClassOf, rdflib.URIRef(s)
        for s in sorted(x for x in same if x > c):
            sup = rdflib.URIRef(s)
            if (sub, OWL.equivalentClass, sup) not in g and (sup, OWL.equivalentClass, sub) not in g:
                yield sub, OWL.equivalentClass, sup


def _annotated(g: rdflib.Graph, sub: rdflib.URIRef, prop: rdflib.URIRef, sup: rdflib.URIRef) -> None:
    g.add((sub, prop, sup))
    axiom = rdflib.BNode()
    g.add((axiom, RDF.type, OWL.Axiom))
    g.add((axiom, OWL.annotatedSource, sub))
    g.add((axiom, OWL.annotatedProperty, prop))
    g.add((axiom, OWL.annotatedTarget, sup))
    g.add((axiom, INFERRED_BY, rdflib.Literal(REASONER)))


def serialise(g: rdflib.Graph, fmt: str) -> bytes:
    """The graph in ``fmt`` (one of :data:`FORMATS`)."""
    if fmt == "turtle":
        return g.serialize(format="turtle", encoding="utf-8")
    rdfxml = g.serialize(format="xml", encoding="utf-8")  # pretty-xml drops statements on list nodes
    if fmt == "rdfxml":
        return rdfxml
    import pyhornedowl

    onto = pyhornedowl.open_ontology_from_string(rdfxml.decode("utf-8"), "owl")
    return onto.save_to_string("owx").encode("utf-8")
