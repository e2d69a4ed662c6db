"""Hardened reading of untrusted input: XML, Turtle and YAML.

Every description, chart, task and cell is read through here. Nothing expands
entities, nothing touches the network, and size and depth are bounded, so a
billion-laughs file, an external entity or a 50 MB file is refused in
milliseconds with a :class:`~plugnproduce.errors.HostileInputError` that names
the file and line.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import rdflib
import yaml
from lxml import etree
from rdflib.plugins.parsers.notation3 import BadSyntax

from plugnproduce.errors import HostileInputError, UnreadableError

MAX_BYTES = 4 * 1024 * 1024
"""Largest description file accepted (descriptions are a few kB; 4 MiB is generous)."""

MAX_XML_DEPTH = 64
"""Deepest XML element nesting accepted."""

_DOCTYPE = re.compile(rb"<!DOCTYPE|<!ENTITY", re.IGNORECASE)


def read_bytes(path: str | Path, limit: int = MAX_BYTES) -> bytes:
    """Read a file whole, refusing one larger than ``limit`` before reading it."""
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > limit:
            raise HostileInputError(f"file is {size} bytes; at most {limit} are accepted", p)
        with p.open("rb") as f:
            data = f.read(limit + 1)
    except OSError as exc:
        raise UnreadableError(f"cannot read file: {exc.strerror or exc}", p) from exc
    if len(data) > limit:
        raise HostileInputError(f"file is larger than the {limit} bytes accepted", p)
    return data


def _line_of(data: bytes, offset: int) -> int:
    return data.count(b"\n", 0, offset) + 1


def refuse_doctype(data: bytes, source: str | Path) -> None:
    """Refuse any DOCTYPE or ENTITY declaration: descriptions never need one."""
    m = _DOCTYPE.search(data)
    if m:
        raise HostileInputError(
            "DOCTYPE/ENTITY declarations are refused (entity expansion is not allowed); "
            "expected a plain XML document",
            source,
            _line_of(data, m.start()),
        )


_PARSER = etree.XMLParser(
    resolve_entities=False,
    no_network=True,
    load_dtd=False,
    dtd_validation=False,
    huge_tree=False,
    remove_comments=False,
)


def parse_xml_bytes(data: bytes, source: str | Path) -> etree._ElementTree:
    """Parse XML from bytes with the hardened parser; errors carry ``source`` and line."""
    refuse_doctype(data, source)
    try:
        root = etree.fromstring(data, parser=_PARSER)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if exc.lineno else None
        msg = exc.msg.split(f", line {line}")[0] if exc.msg else "malformed XML"
        raise UnreadableError(f"malformed XML: {msg}", source, line) from exc
    _check_depth(root, source)
    return root.getroottree()


def parse_xml(path: str | Path) -> etree._ElementTree:
    """Read and parse an XML file with the hardened parser."""
    return parse_xml_bytes(read_bytes(path), path)


def _check_depth(root: etree._Element, source: str | Path) -> None:
    stack = [(root, 1)]
    while stack:
        el, depth = stack.pop()
        if depth > MAX_XML_DEPTH:
            raise HostileInputError(
                f"XML nested {depth} levels deep; at most {MAX_XML_DEPTH} are accepted",
                source,
                el.sourceline,
            )
        stack.extend((child, depth + 1) for child in el)


class _NoAliasLoader(yaml.SafeLoader):
    """A safe YAML loader that refuses anchors and aliases (no YAML bombs)."""

    def compose_node(self, parent: Any, index: Any) -> Any:  # noqa: D102
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise yaml.MarkedYAMLError(
                None, None, "aliases are refused in descriptions", event.start_mark
            )
        event = self.peek_event()
        if getattr(event, "anchor", None):
            raise yaml.MarkedYAMLError(
                None, None, "anchors are refused in descriptions", event.start_mark
            )
        return super().compose_node(parent, index)


def parse_yaml_node(path: str | Path) -> yaml.Node:
    """Read a YAML file into a node tree that keeps line numbers (``node.start_mark.line``)."""
    data = read_bytes(path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UnreadableError(f"not UTF-8 text ({exc.reason})", path) from exc
    try:
        node = yaml.compose(text, Loader=_NoAliasLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        what = exc.problem or exc.context or "malformed YAML"
        raise UnreadableError(f"malformed YAML: {what}", path, line) from exc
    except yaml.YAMLError as exc:
        raise UnreadableError(f"malformed YAML: {exc}", path) from exc
    if node is None:
        raise UnreadableError("empty YAML document", path, 1)
    return node


def read_turtle_text(path: str | Path) -> str:
    """Read a Turtle file as text, bounded in size (rdflib's Turtle parser expands no entities)."""
    data = read_bytes(path)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UnreadableError(f"not UTF-8 text ({exc.reason})", path) from exc


def parse_turtle(path: str | Path) -> tuple[rdflib.Graph, str]:
    """Parse a Turtle file; returns the graph and the text (for line look-ups)."""
    p = Path(path)
    text = read_turtle_text(p)
    g = rdflib.Graph()
    try:
        g.parse(data=text, format="turtle", publicID=p.resolve().as_uri())
    except BadSyntax as exc:
        why = str(getattr(exc, "_why", "") or "syntax error").strip()
        raise UnreadableError(f"malformed Turtle: {why}", p, exc.lines + 1) from exc
    except Exception as exc:  # rdflib raises assorted types for bad literals and IRIs
        raise UnreadableError(f"malformed Turtle: {exc}", p) from exc
    return g, text
