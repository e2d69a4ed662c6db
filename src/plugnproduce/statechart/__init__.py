"""The project's one SCXML layer: model, reader, writer, schema validation and runtime.

- :mod:`~plugnproduce.statechart.model`: a neutral model of a W3C SCXML 1.0 document;
- :func:`read_chart` / :func:`parse_chart` and :func:`write_chart`: SCXML ⇄ model,
  keeping foreign-namespace annotations such as ``pnp:concept``;
- :func:`schema_problems`: validation against the W3C schema, with lines.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names
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

if TYPE_CHECKING:
    from plugnproduce.statechart.io.reader import parse_chart, read_chart
    from plugnproduce.statechart.io.schema import schema_problems
    from plugnproduce.statechart.io.writer import write_chart

_WHERE = {"parse_chart": ".io.reader", "read_chart": ".io.reader", "schema_problems": ".io.schema",
          "write_chart": ".io.writer"}
"""The SCXML reader, writer and schema, imported on first use (:pep:`562`): the model alone (what a description
or a pickled engine holds) needs neither the XML parser nor the description files' safe readers."""

__getattr__, __dir__ = lazy_names(__name__, _WHERE)


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
