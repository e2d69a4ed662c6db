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
from typing import Protocol, cast

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


MAX_YAML_DEPTH = 64
"""Deepest YAML collection nesting accepted."""

_YAML_LOADER: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""libyaml's C parser where PyYAML was built with it (several times faster), else the pure-Python one."""


class _EventParser(Protocol):
    """What is used of a PyYAML loader here: its parser's events (the stubs leave them untyped)."""

    def check_event(self, *choices: type[yaml.Event]) -> bool: ...
    def get_event(self) -> yaml.Event: ...
    def dispose(self) -> None: ...


class _TagResolver(Protocol):
    """What is used of PyYAML's resolver here: the implicit tag of a node."""

    def resolve(self, kind: type[yaml.Node], value: str | None, implicit: bool | tuple[bool, bool] | None) -> str: ...


def _mark(mark: object) -> yaml.Mark:
    """A parser's mark as the nodes take it: libyaml's marks have the same line and column attributes."""
    return cast(yaml.Mark, mark)


def _compose_yaml(text: str, source: str | Path) -> yaml.Node | None:
    """Compose one YAML document into nodes with marks, as ``yaml.compose`` does, but safely.

    The events come from the fastest parser available; the nodes are built here, without
    recursion (libyaml's own composer recurses in C and crashes the process on deep
    nesting), refusing anchors and aliases (no YAML bombs) and nesting beyond
    :data:`MAX_YAML_DEPTH`.
    """
    parser: _EventParser = _YAML_LOADER(text)
    resolver: _TagResolver = yaml.resolver.Resolver()
    stack: list[yaml.CollectionNode] = []
    keys: list[yaml.Node | None] = []
    document: yaml.Node | None = None
    documents = 0
    try:
        while parser.check_event():
            event = parser.get_event()
            if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None):
                what = "aliases" if isinstance(event, yaml.AliasEvent) else "anchors"
                raise yaml.MarkedYAMLError(None, None, f"{what} are refused in descriptions",
                                           _mark(event.start_mark))
            if isinstance(event, yaml.DocumentStartEvent):
                documents += 1
                if documents > 1:
                    raise yaml.composer.ComposerError("expected a single document in the stream", None,
                                               "but found another document", _mark(event.start_mark))
                continue
            node: yaml.Node
            if isinstance(event, yaml.ScalarEvent):
                tag = event.tag if event.tag not in (None, "!") else resolver.resolve(
                    yaml.ScalarNode, event.value, event.implicit)
                node = yaml.ScalarNode(tag, event.value, _mark(event.start_mark), _mark(event.end_mark),
                                       style=event.style or None)  # libyaml says '' for plain
            elif isinstance(event, yaml.CollectionStartEvent):
                kind = yaml.SequenceNode if isinstance(event, yaml.SequenceStartEvent) else yaml.MappingNode
                tag = event.tag if event.tag not in (None, "!") else resolver.resolve(kind, None, event.implicit)
                collection = kind(tag, [], _mark(event.start_mark), None, flow_style=event.flow_style)
                if len(stack) >= MAX_YAML_DEPTH:
                    raise HostileInputError(f"YAML nested more than {MAX_YAML_DEPTH} levels deep; at most "
                                            f"{MAX_YAML_DEPTH} are accepted", source, _mark(event.start_mark).line + 1)
                stack.append(collection)
                keys.append(None)
                continue
            elif isinstance(event, yaml.CollectionEndEvent):
                node = stack.pop()
                node.end_mark = _mark(event.end_mark)
                keys.pop()
            else:  # stream and document ends
                continue
            if not stack:
                document = node
            elif isinstance(stack[-1], yaml.MappingNode):
                if keys[-1] is None:
                    keys[-1] = node
                else:
                    stack[-1].value.append((keys[-1], node))
                    keys[-1] = None
            else:
                stack[-1].value.append(node)
    finally:
        parser.dispose()
    return document


def parse_yaml_node(path: str | Path) -> yaml.Node:
    """Read a YAML file into a node tree that keeps line numbers (``node.start_mark.line``)."""
    data = read_bytes(path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UnreadableError(f"not UTF-8 text ({exc.reason})", path) from exc
    try:
        node = _compose_yaml(text, path)
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
        raise UnreadableError(f"malformed Turtle: {exc.message}", p, exc.lines + 1) from exc
    except Exception as exc:  # rdflib raises assorted types for bad literals and IRIs
        raise UnreadableError(f"malformed Turtle: {exc}", p) from exc
    return g, text
