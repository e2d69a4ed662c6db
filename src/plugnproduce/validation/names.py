"""Names are checked, never dropped: every ontology term a description uses must be known.

A chart's ``pnp:concept`` must name a state concept (on a transition: a request
concept, e.g. ``pnp:SafeStop``) and its ``pnp:accepts`` quantities; a Turtle
description's classes, skills and quantities must be terms of the loaded ontology.
Each unknown name is a finding at its line with the nearest known names.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import rdflib
from rdflib.namespace import OWL, RDF, RDFS

from plugnproduce.description.loader import Loaded
from plugnproduce.ontology.names import turtle_spelling, unknown_class, unknown_term
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP, PNP_IRI, concept_iri, local_name
from plugnproduce.safeio import parse_xml
from plugnproduce.statechart import SCXML_NS
from plugnproduce.validation.findings import Finding

CONCEPT = "{" + PNP_IRI + "}concept"
ACCEPTS = "{" + PNP_IRI + "}accepts"
ROLE = "{" + PNP_IRI + "}role"
TRANSITION = "{" + SCXML_NS + "}transition"

TERM_PROPERTIES = {PNP.hasSkill: "Skill", PNP.requiresSkill: "Skill", PNP.quantity: "Quantity",
                   PNP.mandatoryState: "StateConcept"}
"""Properties whose objects must be terms of a kind."""

DESCRIPTION_CLASSES = {str(PNP.Process), str(PNP.Role), str(PNP.Parameter), str(PNP.Output)}


def chart_name_problems(path: Path, taxonomy: Taxonomy) -> Iterator[Finding]:
    """Unknown state concepts (``pnp:concept``) and quantities (``pnp:accepts``) in a chart."""
    root = parse_xml(path).getroot()
    process_chart = any(el.get(ROLE) for el in root.iter() if isinstance(el.tag, str))
    for el in root.iter():
        if not isinstance(el.tag, str):
            continue
        concept = el.get(CONCEPT)
        if concept and not process_chart:  # a process chart's concepts: see structure.process_problems
            kind = "RequestConcept" if el.tag == TRANSITION else "StateConcept"
            message = unknown_term(concept_iri(concept), kind, taxonomy)
            if message:
                yield Finding(str(path), el.sourceline or 0, f"pnp:concept: {message}")
        for name in (el.get(ACCEPTS) or "").split():
            message = unknown_term(concept_iri(name), "Quantity", taxonomy)
            if message:
                yield Finding(str(path), el.sourceline or 0, f"pnp:accepts: {message}")


def turtle_name_problems(loaded: Loaded, taxonomy: Taxonomy) -> Iterator[Finding]:
    """Unknown classes, skills, quantities and state concepts in a Turtle description."""
    g = loaded.graph
    spell = turtle_spelling(g.namespace_manager)
    for s, c in sorted(g.subject_objects(RDF.type)):
        if not isinstance(c, rdflib.URIRef) or str(c) in DESCRIPTION_CLASSES or taxonomy.knows(str(c)):
            continue
        line = loaded.line(str(s)) or 0
        if str(c).startswith((str(OWL), str(RDFS))):
            yield Finding(str(loaded.path), line, f"{local_name(str(s))} is an ontology term ({local_name(str(c))}); "
                          "a description's class axioms are not read: put them in a library's ontology/ folder")
        else:
            yield Finding(str(loaded.path), line, unknown_class(str(s), str(c), taxonomy, spell))
    for prop, kind in TERM_PROPERTIES.items():
        for s, o in sorted(g.subject_objects(prop)):
            message = unknown_term(str(o), kind, taxonomy, spell)
            if message:
                yield Finding(str(loaded.path), loaded.line(str(s)) or 0, f"{local_name(str(prop))}: {message}")
