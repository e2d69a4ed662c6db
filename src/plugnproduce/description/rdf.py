"""Finding the line where a term is described in a Turtle file."""

from __future__ import annotations

import re

import rdflib


def term_line(text: str, graph: rdflib.Graph, iri: str) -> int | None:
    """The first line where ``iri`` stands as a subject (full or prefixed), if found."""
    spellings = [f"<{iri}>"]
    for prefix, ns in graph.namespaces():
        if iri.startswith(str(ns)) and prefix:
            spellings.append(f"{prefix}:{iri[len(str(ns)):]}")
    pattern = re.compile(r"^\s*(" + "|".join(re.escape(s) for s in spellings) + r")(\s|$)")
    for number, line in enumerate(text.splitlines(), start=1):
        if pattern.match(line):
            return number
    return None
