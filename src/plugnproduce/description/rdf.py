"""A Turtle description as read: its graph, its text and where each term is described, and its values read
with the file and line of any that is missing, repeated or out of range."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from urllib.parse import unquote, urlparse

import rdflib

from plugnproduce.description.where import Where
from plugnproduce.errors import DescriptionError, UnreadableError, excerpt
from plugnproduce.ontology.iris import local_name
from plugnproduce.safeio import parse_turtle, parse_turtle_bytes


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


@dataclass(frozen=True)
class Loaded:
    """A parsed Turtle description: its graph, text and path."""

    path: Path
    graph: rdflib.Graph
    text: str

    def line(self, iri: str) -> int | None:
        """The line where ``iri`` is described in the file."""
        return term_line(self.text, self.graph, iri)

    def where(self, iri: str) -> Where:
        """The place where ``iri`` is described."""
        return Where(str(self.path), self.line(iri))


def read_description(path: str | Path) -> Loaded:
    """Parse a Turtle description file."""
    p = Path(path)
    g, text = parse_turtle(p)
    return Loaded(p, g, text)


def parse_description(data: bytes, path: str | Path) -> Loaded:
    """Parse a Turtle description from bytes as if it were the file at ``path`` (relative IRIs resolve
    against it, messages name it); nothing is read from disk."""
    p = Path(path)
    g, text = parse_turtle_bytes(data, p)
    return Loaded(p, g, text)


def one_value(loaded: Loaded, subject: rdflib.term.Node, prop: rdflib.URIRef, what: str) -> rdflib.term.Node:
    """The one value of ``prop`` on ``subject``; none or several is an error at the subject's line."""
    values = list(loaded.graph.objects(subject, prop))
    if len(values) != 1:
        found = "none" if not values else f"{len(values)} values"
        raise DescriptionError(
            f"{local_name(str(subject))} needs exactly one {what} ({local_name(str(prop))}); found {found}",
            loaded.path,
            loaded.line(str(subject)),
        )
    return values[0]


def optional_value(loaded: Loaded, subject: rdflib.term.Node, prop: rdflib.URIRef) -> rdflib.term.Node | None:
    """A value of ``prop`` on ``subject``, if it has one."""
    return next(iter(loaded.graph.objects(subject, prop)), None)


def file_of(iri: rdflib.term.Node) -> Path:
    """The local path a ``file:`` IRI (a relative reference in a description) names."""
    return Path(unquote(urlparse(str(iri)).path))


def finite_number(loaded: Loaded, subject: rdflib.term.Node, node: rdflib.term.Node | None, what: str) -> float | None:
    """A literal read as a finite number (None if absent); an ill-typed, huge or NaN one is refused at its line."""
    if not isinstance(node, rdflib.Literal):
        return None
    try:
        value = float(node.toPython())
    except (TypeError, ValueError, OverflowError):
        value = math.nan
    if not math.isfinite(value):
        raise UnreadableError(f"{local_name(str(subject))}: {what} {excerpt(str(node))!r} is not a finite number; "
                              "expected a decimal such as 2.5", loaded.path, loaded.line(str(subject)))
    return value


def or_default(value: float | None, default: float) -> float:
    """``value``, or ``default`` when it is absent."""
    return default if value is None else value


def plain_default(node: rdflib.term.Node | None) -> object:
    """A default value as a plain Python value (a decimal as a float, never ``Decimal``)."""
    if not isinstance(node, rdflib.Literal):
        return None
    value = node.toPython()
    return float(value) if isinstance(value, Decimal) else value
