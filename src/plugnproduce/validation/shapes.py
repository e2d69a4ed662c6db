"""The SHACL shapes run by pySHACL over the data graph."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Any

import rdflib
from pyshacl import validate as shacl_validate
from pyshacl.errors import ValidationFailure
from rdflib.namespace import SH
from rdflib.plugins.sparql import prepareQuery
from rdflib.plugins.sparql.operators import register_custom_function
from rdflib.plugins.sparql.sparql import Query

from plugnproduce.description.datagraph import DataGraph
from plugnproduce.errors import OntologyError, tidy
from plugnproduce.ontology.iris import local_name
from plugnproduce.resources import ontology_path
from plugnproduce.safeio import parse_turtle
from plugnproduce.validation.findings import Finding

VERBATIM = rdflib.URIRef("http://plugnproduce.org/shapes#verbatim")
"""The SPARQL function the shapes bind every value a message names with (see :func:`verbatim`)."""


def verbatim(term: rdflib.term.Node) -> rdflib.Literal:
    """``term``'s text, made to come out of pySHACL's message filling as it is.

    pySHACL puts a value into a message's ``{?x}`` as the replacement of ``re.sub``, which reads
    backslashes as escapes: ``a\\u1`` from a task raised ``re.error``, ``\\1`` or ``\\n`` came out
    changed. Doubled, each backslash comes out as one.
    """
    return rdflib.Literal(str(term).replace("\\", "\\\\"))


register_custom_function(VERBATIM, verbatim, override=True)  # type: ignore[arg-type]  # the hint is for raw=True


@lru_cache(maxsize=256)
def _prepared(text: str) -> Query:
    return prepareQuery(text)


class _PreparedQueries(rdflib.Graph):
    """A data graph whose SPARQL queries are parsed once per text.

    pySHACL sends a SPARQL constraint's text again for every focus node it checks, and rdflib parses
    it each time: most of a validation's time went to parsing the same few queries.
    """

    def query(self, query_object: Any, processor: Any = "sparql", result: Any = "sparql",  # noqa: D102 (rdflib's)
              initNs: Any = None, initBindings: Any = None, use_store_provided: bool = True,  # noqa: N803
              **kwargs: Any) -> Any:
        if isinstance(query_object, str) and not initNs and not kwargs:
            query_object = _prepared(query_object)
        return super().query(query_object, processor, result, initNs, initBindings, use_store_provided)


@lru_cache(maxsize=4)
def shapes_graph(path: Path | None = None) -> rdflib.Graph:
    """The shapes file, parsed once."""
    return parse_turtle(path or ontology_path() / "shapes.ttl")[0]


def shape_problems(kg: DataGraph, shapes: rdflib.Graph | None = None) -> list[Finding]:
    """Run the shapes over the data graph; one problem per violation, at its node's place.

    A shape pySHACL cannot run (a SPARQL constraint it refuses, say ``{ SELECT ?x }`` in a
    query's comment, read as a nested select) raises :class:`OntologyError` in one line.
    """
    data = _PreparedQueries(store=kg.graph.store, identifier=kg.graph.identifier)  # the same triples, not a copy
    conforms, results, _ = shacl_validate(
        data,
        shacl_graph=shapes if shapes is not None else shapes_graph(),
        inference="none",
        advanced=True,
        allow_warnings=True,
        inplace=True,  # else the advanced mode copies the data graph into a plain one (and the queries with it)
    )
    if isinstance(results, ValidationFailure):  # pySHACL returns, not raises, a shape it could not run
        raise OntologyError(f"the SHACL shapes could not be run: {tidy(results.message)}")
    if conforms:
        return []
    problems = []
    for result in results.subjects(rdflib.RDF.type, SH.ValidationResult):
        if (None, SH.detail, result) in results:
            continue  # the detail of a result reported in its own words
        focus = results.value(result, SH.focusNode)
        message = tidy(str(results.value(result, SH.resultMessage) or "does not conform"))  # values quoted short
        where = kg.places.get(str(results.value(result, SH.value))) or kg.places.get(str(focus))  # the value's line
        if not message.startswith("step ") and local_name(str(focus)) not in message:
            message = f"{local_name(str(focus))}: {message}"
        problems.append(
            Finding(where.file if where else "<knowledge graph>", (where.line or 0) if where else 0, message)
        )
    return sorted(problems)
