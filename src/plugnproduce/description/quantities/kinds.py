"""The kinds of value a declared datatype takes (``xsd:decimal`` → ``decimal``): what an argument contract, a
process parameter and the reasoner's facts compare. Apart from the contracts, so that reading facts back names
them without loading units."""

from __future__ import annotations

from plugnproduce.ontology.iris import PNP_IRI

XSD = "http://www.w3.org/2001/XMLSchema#"
KINDS = {
    XSD + "decimal": "decimal", XSD + "double": "decimal", XSD + "float": "decimal",
    XSD + "integer": "integer", XSD + "int": "integer", XSD + "long": "integer",
    XSD + "boolean": "boolean", XSD + "string": "string", PNP_IRI + "Pose": "pose",
}
"""Declared datatypes → the kind of value they take."""


def kind_of(datatype: str) -> str:
    """The kind of value a declared datatype takes (``""``: any)."""
    return KINDS.get(datatype, "")
