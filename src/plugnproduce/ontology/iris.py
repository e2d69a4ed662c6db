"""The ontology's names as plain strings: its namespace, and the local names of its IRIs (named in
:mod:`plugnproduce.ontology.vocabulary` too, beside the rdflib terms; what needs only these needs no rdflib)."""

from __future__ import annotations

PNP_IRI = "http://plugnproduce.org/ontology#"


def local_name(iri: str) -> str:
    """The part of an IRI after its last ``#`` or ``/``."""
    cut = max(iri.rfind("#"), iri.rfind("/"))
    return iri[cut + 1 :]


def concept_iri(value: str) -> str:
    """The IRI of a state or quantity concept written as a local name or a full IRI."""
    return value if ":" in value else PNP_IRI + value


def concept_value(iri: str) -> str:
    """How a chart names a concept: its local name in the ``pnp`` namespace, else its full IRI."""
    return iri[len(PNP_IRI):] if iri.startswith(PNP_IRI) else iri
