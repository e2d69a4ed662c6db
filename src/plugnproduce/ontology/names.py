"""Checking names against the taxonomy: an unknown term is reported with the nearest known ones."""

from __future__ import annotations

import difflib
from collections.abc import Callable
from typing import TYPE_CHECKING

from plugnproduce.ontology.iris import concept_value, local_name

if TYPE_CHECKING:  # a Turtle file's spelling needs rdflib; checking names does not
    from rdflib.namespace import NamespaceManager

    from plugnproduce.ontology.taxonomy import Taxonomy

Spelling = Callable[[str], str]
"""How a file writes a term's IRI: a chart's ``pnp:concept`` (:func:`concept_value`), a Turtle prefixed name."""

KIND_WORDS = {
    "Device": "device class",
    "Skill": "skill",
    "StateConcept": "state concept",
    "RequestConcept": "request concept",
    "Quantity": "quantity",
}


def written_name(iri: str) -> str:
    """The name a writer meant: the local name, also of a prefixed name (``lab:Printing`` → ``Printing``)."""
    name = local_name(iri)
    return name.rsplit(":", 1)[-1] if "//" not in name else name


def suggestions(iri: str, candidates: list[str], n: int = 3) -> list[str]:
    """The known terms (IRIs) whose local names are closest to ``iri``'s (best first)."""
    by_name: dict[str, str] = {}
    for c in sorted(candidates):
        by_name.setdefault(local_name(c), c)
    close = difflib.get_close_matches(written_name(iri), list(by_name), n=n, cutoff=0.6)
    if not close:  # also compare case-insensitively: "parallelgripper"
        lowered = {k.lower(): k for k in by_name}
        close = [lowered[c] for c in difflib.get_close_matches(written_name(iri).lower(), list(lowered), n=n,
                                                              cutoff=0.6)]
    return [by_name[c] for c in close]


def did_you_mean(iri: str, candidates: list[str], spell: Spelling = concept_value) -> str:
    """``"; did you mean X or Y?"`` for the nearest known terms, each written as ``spell`` writes it (by
    default as a chart or task names a concept: a ``pnp`` term by its local name, any other by its full
    IRI), or nothing when none is near."""
    close = [spell(c) for c in suggestions(iri, candidates)]
    return f"; did you mean {' or '.join(close)}?" if close else ""


def unknown_term(iri: str, kind: str, taxonomy: Taxonomy, spell: Spelling = concept_value) -> str | None:
    """A message if ``iri`` is not a term of ``kind`` (a key of :data:`KIND_WORDS`), else None; its
    suggestions are written as ``spell`` writes a term (see :func:`did_you_mean`)."""
    if taxonomy.is_kind(iri, kind):
        return None
    word = KIND_WORDS[kind]
    near = prefixed_hint(iri, spell) + did_you_mean(iri, taxonomy.classes_of_kind(kind), spell)
    if taxonomy.knows(iri):
        return f"{local_name(iri)} is not a {word} of the ontology ({iri})" + near
    return f"unknown {word} {local_name(iri)} ({iri})" + near


def prefixed_hint(iri: str, spell: Spelling) -> str:
    """A chart names a term of another namespace by its full IRI: say so for a prefixed name there."""
    if spell is concept_value and ":" in iri and "//" not in iri:
        return "; a chart does not expand prefixed names: write the full IRI"
    return ""


def turtle_spelling(namespaces: NamespaceManager) -> Spelling:
    """How a Turtle file writes a term: a prefixed name with the file's own prefixes, else ``<IRI>``."""
    import rdflib

    return lambda iri: namespaces.normalizeUri(rdflib.URIRef(iri))


def unknown_class(subject: str, cls: str, taxonomy: Taxonomy, spell: Spelling = concept_value) -> str:
    """The message for ``subject`` typed with a class the ontology does not know."""
    return (f"{local_name(subject)} is of unknown class {local_name(cls)} ({cls})"
            + did_you_mean(cls, taxonomy.classes_of_kind("Device"), spell))
