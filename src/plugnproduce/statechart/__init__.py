"""The project's one SCXML layer: model, reader, writer, schema validation and runtime.

- :mod:`~plugnproduce.statechart.model`: a neutral model of a W3C SCXML 1.0 document;
- :func:`read_chart` / :func:`parse_chart` and :func:`write_chart`: SCXML ⇄ model,
  keeping foreign-namespace annotations such as ``pnp:concept``;
- :func:`schema_problems`: validation against the W3C schema, with lines.
"""

from __future__ import annotations

from plugnproduce.statechart.io.reader import parse_chart, read_chart
from plugnproduce.statechart.io.schema import schema_problems
from plugnproduce.statechart.io.writer import write_chart
from plugnproduce.statechart.model import (
    CONCEPT,
    PNP_NS,
    SCXML_NS,
    Chart,
    Final,
    History,
    Parallel,
    State,
    Transition,
    concept,
    iter_states,
)

__all__ = [
    "CONCEPT",
    "PNP_NS",
    "SCXML_NS",
    "Chart",
    "Final",
    "History",
    "Parallel",
    "State",
    "Transition",
    "concept",
    "iter_states",
    "parse_chart",
    "read_chart",
    "schema_problems",
    "write_chart",
]
