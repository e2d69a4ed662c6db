"""TBox files as Protégé saves them: Turtle, RDF/XML and OWL/XML, and their ``owl:imports``.

A file's format is told by its content, not its name (Protégé saves any format as ``.owl``):
an XML document whose root is ``rdf:RDF`` is RDF/XML, one whose root is OWL's ``Ontology`` is
OWL/XML, anything else is Turtle. XML is screened first by the hardened reader (no DOCTYPE, no
entities, bounded size and depth: rdflib's RDF/XML parser hangs on a billion-laughs file), then
rdflib reads RDF/XML and owlready2 reads OWL/XML.

``owl:imports`` never goes to the network: an imported IRI is the ``pnp`` ontology (always
loaded), or a file a Protégé catalog (``catalog-v001.xml`` beside the importing file or in the
library's ``ontology/`` folder) maps it to, or a file of the library that declares that
ontology IRI. The file must lie inside the library folder. Anything else is bad input naming the IRI.
"""

from __future__ import annotations

import io
import warnings
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import unquote, urljoin, urlparse

from plugnproduce.deferred import dataclass
from plugnproduce.digests import sha256
from plugnproduce.errors import DescriptionError, HostileInputError, UnreadableError, tidy

if TYPE_CHECKING:  # the parsers are imported when a file is read: listing the files needs none of them
    import rdflib
    from lxml import etree

TBOX_SUFFIXES = (".ttl", ".owl", ".rdf", ".owx")
"""The file names a library's ``ontology/`` folder is read for (``shapes.ttl`` excepted)."""

CATALOG = "catalog-v001.xml"
"""The name Protégé gives its import catalog."""

PNP_ONTOLOGY = "http://plugnproduce.org/ontology"
"""The IRI of the built-in ontology: an import of it is always satisfied."""

RDF_XML_ROOT = "{http://www.w3.org/1999/02/22-rdf-syntax-ns#}RDF"
OWL_XML_ROOT = "{http://www.w3.org/2002/07/owl#}Ontology"
_CATALOG_NS = "urn:oasis:names:tc:entity:xmlns:xml:catalog"


@dataclass(frozen=True)
class TBoxFile:
    """One TBox file read: its graph, its format (``turtle``, ``rdfxml``, ``owlxml``), its text and,
    for XML formats, its element tree (for the lines axioms are written at)."""

    path: Path
    graph: rdflib.Graph
    format: str
    text: str
    tree: etree._ElementTree | None = None


_READ: dict[tuple[str, str], TBoxFile] = {}
_READ_MOST = 256


def read_tbox_file(path: Path) -> TBoxFile:
    """Read one TBox file in whichever of the three formats it is; parsed once per content."""
    from plugnproduce.safeio import read_bytes  # the hardened readers: when a file is read, not when one is listed

    p = Path(path)
    data = read_bytes(p)
    key = (str(p), sha256(data).hexdigest())
    if key not in _READ:
        if len(_READ) >= _READ_MOST:
            _READ.clear()
        _READ[key] = _read(p, data)
    return _READ[key]


def _read(path: Path, data: bytes) -> TBoxFile:
    from plugnproduce.safeio import MAX_TRIPLES, parse_turtle_bytes, parse_xml_bytes

    if not data.lstrip(b"\xef\xbb\xbf \t\r\n").startswith(b"<"):
        g, text = parse_turtle_bytes(data, path)
        return TBoxFile(path, g, "turtle", text)
    tree = parse_xml_bytes(data, path)  # refuses DOCTYPE and entities before any RDF parser sees the bytes
    root = tree.getroot().tag
    if root == RDF_XML_ROOT:
        graph, fmt = _rdfxml(data, path), "rdfxml"
    elif root == OWL_XML_ROOT:
        graph, fmt = _owlxml(data, path), "owlxml"
    else:
        raise UnreadableError(f"an XML document with root <{tidy(str(root))}>; expected RDF/XML (rdf:RDF) or "
                              "OWL/XML (owl:Ontology), or Turtle", path, tree.getroot().sourceline)
    if len(graph) > MAX_TRIPLES:
        raise HostileInputError(f"{len(graph)} triples; at most {MAX_TRIPLES} are accepted in one file", path)
    return TBoxFile(path, graph, fmt, data.decode("utf-8", errors="replace"), tree)


def _rdfxml(data: bytes, path: Path) -> rdflib.Graph:
    import rdflib

    g = rdflib.Graph()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g.parse(data=data, format="xml", publicID=path.resolve().as_uri())
    except Exception as exc:  # rdflib raises assorted types (SAX errors, ParserError) for bad RDF/XML
        line = getattr(exc, "getLineNumber", lambda: None)()
        raise UnreadableError(f"malformed RDF/XML: {tidy(str(exc))}", path, line) from exc
    return g


def _owlxml(data: bytes, path: Path) -> rdflib.Graph:
    """OWL/XML to triples with owlready2's OWL/XML parser alone: loading it as an owlready2 ontology would
    fetch its ``Import`` IRIs from the network."""
    import rdflib
    from owlready2.owlxml_2_ntriples import parse

    g = rdflib.Graph()
    blanks: dict[str, rdflib.BNode] = {}

    def term(x: str) -> rdflib.term.Node:
        return blanks.setdefault(x, rdflib.BNode()) if x.startswith("_:") else rdflib.URIRef(x)

    def obj(s: str, p: str, o: str) -> None:
        g.add((term(s), rdflib.URIRef(p), term(o)))

    def data_(s: str, p: str, o: object, d: str | None) -> None:
        lit = (rdflib.Literal(o, lang=d[1:]) if d and d.startswith("@")
               else rdflib.Literal(o, datatype=rdflib.URIRef(d) if d else None))
        g.add((term(s), rdflib.URIRef(p), lit))

    try:
        parse(io.BytesIO(data), obj, data_, default_base=path.resolve().as_uri())
    except Exception as exc:  # owlready2's parser raises its own and expat's errors
        line = getattr(exc, "lineno", None)
        raise UnreadableError(f"malformed OWL/XML: {tidy(str(exc).splitlines()[0] if str(exc) else repr(exc))}",
                              path, line) from exc
    return g


def folder_files(folder: Path) -> list[Path]:
    """The TBox files directly in an ontology folder: every Turtle, RDF/XML and OWL/XML file but SHACL shapes."""
    return sorted(p for p in folder.iterdir()
                  if p.suffix.lower() in TBOX_SUFFIXES and p.name != "shapes.ttl" and p.is_file())


def with_imports(files: Iterable[Path], root: Path) -> list[Path]:
    """``files`` followed by every file they import (transitively), each once; imports resolve inside ``root``."""
    from rdflib.namespace import OWL

    out: list[Path] = []
    queue = [Path(f) for f in files]
    while queue:
        f = queue.pop(0)
        if f.resolve() in {o.resolve() for o in out}:
            continue
        out.append(f)
        tbox = read_tbox_file(f)
        for iri in sorted(str(o) for o in tbox.graph.objects(None, OWL.imports)):
            target = resolve_import(iri, tbox, root)
            if target is not None:
                queue.append(target)
    return out


def resolve_import(iri: str, importer: TBoxFile, root: Path) -> Path | None:
    """The file ``iri`` names for ``importer`` (None for the built-in ontology), or bad input naming the IRI."""
    if iri.rstrip("#/") == PNP_ONTOLOGY:
        return None
    root = root.resolve()
    for catalog in _catalogs(importer.path, root):
        target = _catalog_entry(catalog, iri)
        if target is not None:
            return _inside(target, root, importer, iri, f"{catalog.name} maps it to {target}")
    parsed = urlparse(iri)
    if parsed.scheme == "file" and Path(unquote(parsed.path)).is_file():
        return _inside(Path(unquote(parsed.path)), root, importer, iri, "its file")
    for candidate in _library_tbox(root):
        if candidate.resolve() != importer.path.resolve() and iri.rstrip("#/") in _declared(candidate):
            return candidate
    raise UnreadableError(f"owl:imports <{iri}> is not resolved: no {CATALOG} maps it and no file of the library "
                           f"{root} declares that ontology (imports are never fetched from the network)",
                           importer.path, _line_naming(importer.text, iri))


def _catalogs(importer: Path, root: Path) -> list[Path]:
    places = [importer.resolve().parent, root / "ontology", root]
    return [c for c in dict.fromkeys(p / CATALOG for p in places) if c.is_file()]


def _catalog_entry(catalog: Path, iri: str) -> Path | None:
    """The file a Protégé catalog maps ``iri`` to (its ``uri`` entries; relative to the catalog or its xml:base)."""
    from plugnproduce.safeio import parse_xml_bytes, read_bytes

    tree = parse_xml_bytes(read_bytes(catalog), catalog)
    for el in tree.getroot().iter(f"{{{_CATALOG_NS}}}uri"):
        if el.get("name", "").rstrip("#/") == iri.rstrip("#/") and el.get("uri"):
            base = el.base or catalog.resolve().as_uri()
            target = urljoin(base if "://" in base or base.startswith("file:") else catalog.resolve().as_uri(),
                             el.get("uri", ""))
            parsed = urlparse(target)
            if parsed.scheme not in ("file", ""):
                raise UnreadableError(f"{CATALOG} maps <{iri}> to {tidy(target)}, which is not a local file "
                                       "(imports are never fetched from the network)", catalog, el.sourceline)
            return Path(unquote(parsed.path))
    return None


def _inside(target: Path, root: Path, importer: TBoxFile, iri: str, how: str) -> Path:
    resolved = target.resolve()
    if not resolved.is_relative_to(root) or not resolved.is_file():
        where = "is outside the library folder" if not resolved.is_relative_to(root) else "does not exist"
        raise UnreadableError(f"owl:imports <{iri}> is not resolved: {how}, which {where}", importer.path,
                               _line_naming(importer.text, iri))
    return resolved


def _library_tbox(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*") if p.suffix.lower() in TBOX_SUFFIXES and p.name != "shapes.ttl"
                  and p.is_file())


def _declared(path: Path) -> set[str]:
    """The ontology IRIs a file declares (``<iri> a owl:Ontology``); an unreadable file declares none."""
    from rdflib.namespace import OWL, RDF

    try:
        g = read_tbox_file(path).graph
    except DescriptionError:
        return set()
    return {str(s).rstrip("#/") for s in g.subjects(RDF.type, OWL.Ontology)}


def _line_naming(text: str, iri: str) -> int | None:
    """The first line of ``text`` naming ``iri`` (whole or by its last part), for messages."""
    for needle in (iri, iri.rstrip("#/").rsplit("/", 1)[-1]):
        for n, line in enumerate(text.splitlines(), 1):
            if needle and needle in line and "mport" in line:
                return n
    return None
