"""Validation against the W3C SCXML 1.0 schema (vendored in ``w3c/``, licence in scxml-copyright.xsd).

``xmlschema`` is used because it also reports dangling ``target``/``initial`` IDREFs
and duplicate ids, which libxml2 does not.
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

from lxml import etree

from plugnproduce.errors import DescriptionError, tidy
from plugnproduce.resources import package_file
from plugnproduce.safeio import parse_xml_bytes

if TYPE_CHECKING:  # imported when a schema is first needed: it is slow to import
    import xmlschema


@lru_cache(maxsize=1)
def scxml_schema() -> xmlschema.XMLSchema:
    """The W3C SCXML schema, loaded once (from package data; nothing is fetched)."""
    import xmlschema

    return xmlschema.XMLSchema(str(package_file("statechart", "io", "w3c", "scxml.xsd")))


def schema_problems(data: bytes, source: str | Path) -> list[DescriptionError]:
    """Every way the document breaks the W3C SCXML schema, each with its line."""
    tree = parse_xml_bytes(data, source)  # hardened: refuses DOCTYPE, entities, oversize
    problems = []
    for error in scxml_schema().iter_errors(tree):
        reason = (error.reason or str(error.message)).rstrip(".")
        line = _line(tree, error, reason)
        problems.append(DescriptionError(f"not valid W3C SCXML: {tidy(reason)}", source, line))
    return problems


_IDREF = re.compile(r"IDREF '([^']+)' not found")
_CHILD = re.compile(r"Unexpected child with tag '[^']+' at position (\d+)")


def _line(tree: etree._ElementTree, error: xmlschema.XMLSchemaValidationError, reason: str) -> int | None:
    """The line of the element an error is about; for a dangling IDREF, the element that uses it."""
    dangling = _IDREF.search(reason)
    if dangling:
        token = dangling.group(1)
        for el in tree.getroot().iter():
            if any(token in (el.get(a) or "").split() for a in ("target", "initial")):
                return el.sourceline  # type: ignore[no-any-return]
    element = error.elem
    if not isinstance(element, etree._Element):
        return None
    child = _CHILD.search(reason)
    if child:  # xmlschema names the parent; point at the unexpected child itself
        children = [c for c in element if isinstance(c.tag, str)]
        position = int(child.group(1))
        if 0 < position <= len(children):
            return children[position - 1].sourceline  # type: ignore[no-any-return]
    return element.sourceline  # type: ignore[no-any-return]
