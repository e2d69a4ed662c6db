"""Hardened reading of untrusted input: XML, Turtle and YAML.

Every description, chart, task and cell is read through here. Nothing expands
entities, nothing touches the network, and size and depth are bounded, so a
billion-laughs file, an external entity or a 50 MB file is refused in
milliseconds with a :class:`~plugnproduce.errors.HostileInputError` that names
the file and line.
"""

from __future__ import annotations

import codecs
import re
import stat
import warnings
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, cast

import yaml

from plugnproduce.errors import HostileInputError, UnreadableError, excerpt, shorten_words, tidy

if TYPE_CHECKING:  # the XML and Turtle parsers are imported by the first file of their kind: a command that reads
    # only YAML, or only what it kept in the cache folder, pays for neither
    import rdflib
    from lxml import etree

MAX_BYTES = 4 * 1024 * 1024
"""Largest description file accepted (descriptions are a few kB; 4 MiB is generous)."""

MAX_XML_DEPTH = 64
"""Deepest XML element nesting accepted."""

_DOCTYPE = re.compile(r"<!DOCTYPE|<!ENTITY", re.IGNORECASE)
_COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)
_WIDE = (  # (leading bytes, codec) of the encodings whose text the byte-wise search would miss
    (codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"),
    (b"<\0\0\0", "utf-32-le"), (b"\0\0\0<", "utf-32-be"), (b"<\0", "utf-16-le"), (b"\0<", "utf-16-be"),
)


def shown(path: str | Path) -> str:
    """A path as an error message names it: whole, or its ends if it is so long it must come from the input."""
    text = str(path)
    return text if len(text) <= 200 else excerpt(text, 120)


def read_bytes(path: str | Path, limit: int = MAX_BYTES) -> bytes:
    """Read a file whole, refusing one larger than ``limit`` before reading it."""
    p = Path(path)
    where = shown(p)
    try:
        info = p.stat()
        if not stat.S_ISREG(info.st_mode):  # a FIFO or a device would block the reader; a folder is no file
            raise UnreadableError("not a regular file (a folder, pipe or device); expected a description file", where)
        size = info.st_size
        if size > limit:
            raise HostileInputError(f"file is {size} bytes; at most {limit} are accepted", where)
        with p.open("rb") as f:
            data = f.read(limit + 1)
    except OSError as exc:
        raise UnreadableError(f"cannot read file: {exc.strerror or exc}", where) from exc
    except ValueError as exc:  # a NUL in the path (a chart named <a%00b.scxml>)
        raise UnreadableError("cannot read file: its name holds a NUL character", where) from exc
    if len(data) > limit:
        raise HostileInputError(f"file is larger than the {limit} bytes accepted", where)
    return data


def _as_text(data: bytes) -> str:
    """The document as text for the DOCTYPE search: wide encodings decoded, any other byte for byte."""
    for start, codec in _WIDE:
        if data.startswith(start):
            return data.decode(codec, errors="replace")
    return data.decode("latin-1")  # ASCII-compatible encodings: '<!DOCTYPE' is the same bytes in each


def refuse_doctype(data: bytes, source: str | Path) -> None:
    """Refuse any DOCTYPE or ENTITY declaration, in whatever encoding; text inside comments does not count."""
    text = _as_text(data)
    blanked = _COMMENT.sub(lambda m: "\n" * m.group().count("\n"), text)  # keep line numbers
    m = _DOCTYPE.search(blanked)
    if m:
        raise HostileInputError(
            "DOCTYPE/ENTITY declarations are refused (entity expansion is not allowed); "
            "expected a plain XML document",
            source,
            blanked.count("\n", 0, m.start()) + 1,
        )


@lru_cache(maxsize=1)
def _parser() -> etree.XMLParser:
    from lxml import etree

    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
        remove_comments=False,
    )


def parse_xml_bytes(data: bytes, source: str | Path) -> etree._ElementTree:
    """Parse XML from bytes with the hardened parser; errors carry ``source`` and line."""
    from lxml import etree

    refuse_doctype(data, source)
    try:
        root = etree.fromstring(data, parser=_parser())
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if exc.lineno else None
        msg = exc.msg.split(f", line {line}")[0] if exc.msg else "the parser gave no reason"
        raise UnreadableError(f"malformed XML: {tidy(shorten_words(msg))}", source, line) from exc
    tree = root.getroottree()
    if tree.docinfo.internalDTD is not None:  # an encoding the search did not know (any DOCTYPE makes one)
        raise HostileInputError("DOCTYPE/ENTITY declarations are refused (entity expansion is not allowed); "
                                "expected a plain XML document", source, 1)
    _check_depth(root, source)
    return tree


def parse_xml(path: str | Path) -> etree._ElementTree:
    """Read and parse an XML file with the hardened parser."""
    return parse_xml_bytes(read_bytes(path), path)


MAX_XML_ELEMENTS = 200_000
"""Most elements in one XML document."""

MAX_XML_ATTRIBUTES = 64
"""Most attributes on one XML element."""


def _check_depth(root: etree._Element, source: str | Path) -> None:
    """Refuse documents nested too deep, with too many elements, or an element with too many attributes."""
    stack = [(root, 1)]
    count = 0
    while stack:
        el, depth = stack.pop()
        count += 1
        if depth > MAX_XML_DEPTH:
            raise HostileInputError(
                f"XML nested {depth} levels deep; at most {MAX_XML_DEPTH} are accepted",
                source,
                el.sourceline,
            )
        if count > MAX_XML_ELEMENTS:
            raise HostileInputError(f"more than {MAX_XML_ELEMENTS} XML elements", source, el.sourceline)
        if len(el.attrib) > MAX_XML_ATTRIBUTES:
            raise HostileInputError(f"an element with {len(el.attrib)} attributes; at most {MAX_XML_ATTRIBUTES} "
                                    "are accepted", source, el.sourceline)
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


def _too_deep(source: str | Path, line: int | None) -> HostileInputError:
    """The one refusal of deep nesting, whichever layer finds it first: our composer, or libyaml's
    scanner (PyYAML 6.0.4 and later stop at about 1,000 levels while reading ahead)."""
    return HostileInputError(f"YAML nested more than {MAX_YAML_DEPTH} levels deep; at most {MAX_YAML_DEPTH} are "
                             "accepted", source, line)


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
                collection = kind(tag, [], _mark(event.start_mark), flow_style=event.flow_style)  # end mark: at its end
                if len(stack) >= MAX_YAML_DEPTH:
                    raise _too_deep(source, _mark(event.start_mark).line + 1)
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


_SafeDumper: type[yaml.SafeDumper] = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
"""libyaml's emitter where PyYAML has it: the same text as PyYAML's own, a fourth of the time (the repairs of a
10,000-step task are written out whole)."""


class PlainDumper(_SafeDumper):  # type: ignore[valid-type,misc]
    """A YAML writer that never writes anchors and aliases, which :func:`parse_yaml_node` refuses.

    A value shared by two places (one pose in two steps) is written out at each.
    """

    def ignore_aliases(self, data: Any) -> bool:  # noqa: D102
        return True


def parse_yaml_node(path: str | Path) -> yaml.Node:
    """Read a YAML file into a node tree that keeps line numbers (``node.start_mark.line``)."""
    return parse_yaml_bytes(read_bytes(path), path)


def parse_yaml_bytes(data: bytes, source: str | Path) -> yaml.Node:
    """Parse YAML text (UTF-8, at most :data:`MAX_BYTES`) into a node tree that keeps line numbers;
    ``source`` names the text in error messages (a file name, an upload's name)."""
    if len(data) > MAX_BYTES:
        raise HostileInputError(f"file is {len(data)} bytes; at most {MAX_BYTES} are accepted", source)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UnreadableError(f"not UTF-8 text ({exc.reason})", source) from exc
    try:
        node = _compose_yaml(text, source)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        what = exc.problem or exc.context or "malformed YAML"
        if "nesting depth" in what:
            raise _too_deep(source, line) from exc
        raise UnreadableError(f"malformed YAML: {tidy(what)}", source, line) from exc
    except yaml.reader.ReaderError as exc:  # a character YAML does not allow (NUL, other controls)
        # the refused character is its first occurrence (libyaml gives its position in bytes, not characters)
        line = text[:text.find(chr(exc.character))].count("\n") + 1
        raise UnreadableError(f"malformed YAML: {tidy(exc.reason)} (character #x{exc.character:04x}); "
                              "expected printable text", source, line) from exc
    except yaml.YAMLError as exc:
        raise UnreadableError(f"malformed YAML: {tidy(str(exc))}", source) from exc
    if node is None:
        raise UnreadableError("empty YAML document", source, 1)
    _check_yaml_values(node, source)
    return node


MAX_DIGITS = 30
"""Longest integer (in digits) a description may hold."""

_PLAIN_TAGS = {f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "bool", "null", "seq", "map")}
_NOT_A_NUMBER = re.compile(r"^[-+]?\.(nan|inf)$", re.IGNORECASE)


def _check_yaml_values(root: yaml.Node, path: str | Path) -> None:
    """Refuse what a description never needs and what would crash or blow up its reading:
    tags other than plain data (``!!timestamp``, ``!!omap``, ``!!binary``, ...), NaN and
    infinities, integers of more than :data:`MAX_DIGITS` digits, nesting deeper than
    :data:`MAX_YAML_DEPTH`, a key that is a list or a mapping (``? [a]: 1``: no plain value
    can be built of it)."""
    stack: list[tuple[yaml.Node, int]] = [(root, 1)]
    while stack:
        node, depth = stack.pop()
        line = node.start_mark.line + 1
        if depth > MAX_YAML_DEPTH:
            raise HostileInputError(f"YAML nested {depth} levels deep; at most {MAX_YAML_DEPTH} are accepted",
                                    path, line)
        if node.tag not in _PLAIN_TAGS:
            raise UnreadableError(f"YAML type {node.tag.replace('tag:yaml.org,2002:', '!!')} is not accepted; "
                                  "expected text, numbers, true/false, lists and mappings (quote a value to mean "
                                  "text)", path, line)
        if isinstance(node, yaml.ScalarNode):
            _check_scalar(node, path, line)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((child, depth + 1) for child in node.value)
        else:
            for key, _ in node.value:
                if not isinstance(key, yaml.ScalarNode):
                    raise UnreadableError("malformed YAML: a key is a list or a mapping; expected a plain name", path,
                                          key.start_mark.line + 1)
            stack.extend((part, depth + 1) for pair in node.value for part in pair)


def _check_scalar(node: yaml.ScalarNode, path: str | Path, line: int) -> None:
    value = str(node.value)
    if node.tag.endswith(":float") and _NOT_A_NUMBER.match(value.strip()):
        raise UnreadableError(f"{value.strip()} is not a number a device can be given; expected a finite number",
                              path, line)
    if node.tag.endswith(":int") and sum(c.isdigit() for c in value) > MAX_DIGITS:
        raise UnreadableError(f"an integer of {sum(c.isdigit() for c in value)} digits; at most {MAX_DIGITS} "
                              "are accepted", path, line)


MAX_PREFIXES = 500
"""Most prefix declarations in one Turtle file (rdflib's parser is quadratic in them)."""

MAX_TRIPLES = 50_000
"""Most triples in one Turtle file (a description has tens, an ontology extension hundreds)."""

_PREFIX = re.compile(r"^[ \t]*(@prefix|prefix)\b", re.IGNORECASE | re.MULTILINE)


def _turtle_text(data: bytes, source: str | Path) -> str:
    if len(data) > MAX_BYTES:
        raise HostileInputError(f"file is {len(data)} bytes; at most {MAX_BYTES} are accepted", source)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise UnreadableError(f"not UTF-8 text ({exc.reason})", source) from exc
    for count, m in enumerate(_PREFIX.finditer(text), start=1):
        if count > MAX_PREFIXES:
            raise HostileInputError(f"more than {MAX_PREFIXES} prefix declarations", source,
                                    text.count("\n", 0, m.start()) + 1)
    return text


def parse_turtle(path: str | Path) -> tuple[rdflib.Graph, str]:
    """Parse a Turtle file; returns the graph and the text (for line look-ups)."""
    return parse_turtle_bytes(read_bytes(path), path)


def parse_turtle_bytes(data: bytes, path: str | Path) -> tuple[rdflib.Graph, str]:
    """Parse Turtle text as if it were the file at ``path`` (its relative IRIs resolve against it, and
    messages name it); returns the graph and the text (for line look-ups). Nothing is read from ``path``."""
    import rdflib
    from rdflib.plugins.parsers.notation3 import BadSyntax

    p = Path(path)
    text = _turtle_text(data, p)
    g = rdflib.Graph()
    try:
        with warnings.catch_warnings():  # rdflib warns (and logs) about odd literals and IRIs: no chatter
            warnings.simplefilter("ignore")
            g.parse(data=text, format="turtle", publicID=p.resolve().as_uri())
    except BadSyntax as exc:  # its str() is several lines quoting the file: keep the reason only
        raise UnreadableError(f"malformed Turtle: {tidy(exc._why)}", p, exc.lines + 1) from exc
    except Exception as exc:  # rdflib raises assorted types for bad literals and IRIs
        raise UnreadableError(f"malformed Turtle: {tidy(str(exc))}", p) from exc
    if len(g) > MAX_TRIPLES:
        raise HostileInputError(f"{len(g)} triples; at most {MAX_TRIPLES} are accepted in one file", p)
    return g, text
