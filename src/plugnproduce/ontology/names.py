"""Checking names against the taxonomy: an unknown term is reported with the nearest known ones."""

from __future__ import annotations

import difflib

from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import local_name

KIND_WORDS = {
    "Device": "device class",
    "Skill": "skill",
    "StateConcept": "state concept",
    "RequestConcept": "request concept",
    "Quantity": "quantity",
}


def suggestions(iri: str, candidates: list[str], n: int = 3) -> list[str]:
    """The known terms whose local names are closest to ``iri``'s (best first)."""
    by_name = {local_name(c): c for c in candidates}
    close = difflib.get_close_matches(local_name(iri), list(by_name), n=n, cutoff=0.6)
    if not close:  # also compare case-insensitively: "parallelgripper"
        lowered = {k.lower(): k for k in by_name}
        close = [lowered[c] for c in difflib.get_close_matches(local_name(iri).lower(), list(lowered), n=n,
                                                              cutoff=0.6)]
    return close


def did_you_mean(iri: str, candidates: list[str]) -> str:
    """``"; did you mean X or Y?"`` for the nearest known terms, or nothing when none is near."""
    close = suggestions(iri, candidates)
    return f"; did you mean {' or '.join(close)}?" if close else ""


def unknown_term(iri: str, kind: str, taxonomy: Taxonomy) -> str | None:
    """A message if ``iri`` is not a term of ``kind`` (a key of :data:`KIND_WORDS`), else None."""
    if taxonomy.is_kind(iri, kind):
        return None
    word = KIND_WORDS[kind]
    if taxonomy.knows(iri):
        return f"{local_name(iri)} is not a {word} of the ontology ({iri})" + did_you_mean(
            iri, taxonomy.classes_of_kind(kind))
    return f"unknown {word} {local_name(iri)} ({iri})" + did_you_mean(iri, taxonomy.classes_of_kind(kind))


def unknown_class(subject: str, cls: str, taxonomy: Taxonomy) -> str:
    """The message for ``subject`` typed with a class the ontology does not know."""
    return (f"{local_name(subject)} is of unknown class {local_name(cls)} ({cls})"
            + did_you_mean(cls, taxonomy.classes_of_kind("Device")))
