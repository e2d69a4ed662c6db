"""OWL evidence for explanations: the asserted TBox axioms with the ``file:line`` they are written at (the Turtle
statement's line; the element's line in RDF/XML and OWL/XML), labels in
plain words (rdfs:label, by language tag), and minimal justifications of what the reasoner derived.

HermiT (through owlready2) answers *whether* a class is subsumed or implies a skill, but gives no justification.
A justification is therefore computed here: the shortest chain of asserted axioms (named subclass and
equivalence axioms, and ``C ⊑ ∃hasSkill.S`` restrictions) that entails the fact. A chain of one axiom means the
fact is asserted; a longer one means the reasoner inferred it. Every justification is offered only when the
reasoner's closure agrees with it.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import rdflib
from rdflib.namespace import OWL, RDFS

from plugnproduce.description.model import Where
from plugnproduce.ontology.sources import read_tbox_file
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP, local_name
from plugnproduce.ontology.xmllines import axiom_line

DEFAULT_LANGUAGE = "en"
"""The language of an untagged rdfs:label."""


@dataclass(frozen=True)
class Axiom:
    """One asserted TBox axiom and where it is written: ``sub ⊑ sup`` (kind ``subclass``), ``sub ≡ sup``
    (``equivalent``), ``sub ⊑ ∃hasSkill.sup`` (``has_skill``), ``sub ⊑ ∃prop.sup`` (``some``), or a definition
    ``sub ≡ C1 ⊓ ∃p.C2 ⊓ …`` (``defined``, its conjuncts in ``parts`` as (property or "", class)).

    A definition also yields the subclass and restriction axioms it entails (``sub ⊑ C1``…), each shown as
    the definition it comes from (``shown``)."""

    kind: str
    sub: str
    sup: str
    where: Where
    prop: str = ""
    parts: tuple[tuple[str, str], ...] = ()
    shown: str = ""

    def formula(self) -> str:
        """The axiom in DL notation with local names, e.g. ``ParallelGripper ⊑ ∃hasSkill.CanParallelGrip``."""
        if self.shown:
            return self.shown
        a, b = local_name(self.sub), local_name(self.sup)
        if self.kind == "defined":
            return f"{a} ≡ " + " ⊓ ".join(f"∃{local_name(p)}.{local_name(c)}" if p else local_name(c)
                                          for p, c in self.parts)
        return {"subclass": f"{a} ⊑ {b}", "equivalent": f"{a} ≡ {b}",
                "some": f"{a} ⊑ ∃{local_name(self.prop)}.{b}"}.get(self.kind, f"{a} ⊑ ∃hasSkill.{b}")


class Labels:
    """rdfs:label of every term, by language tag; an untagged label counts as :data:`DEFAULT_LANGUAGE`."""

    def __init__(self, labels: dict[tuple[str, str], str], fallback: dict[str, str] | None = None):
        self._labels = labels
        self._fallback = fallback or {}

    @classmethod
    def from_graph(cls, g: rdflib.Graph, fallback: dict[str, str] | None = None) -> Labels:
        """The labels a graph states."""
        out: dict[tuple[str, str], str] = {}
        for s, o in g.subject_objects(RDFS.label):
            if isinstance(s, rdflib.URIRef) and isinstance(o, rdflib.Literal):
                out.setdefault((str(s), (o.language or DEFAULT_LANGUAGE).lower()), str(o))
        return cls(out, fallback)

    def label(self, iri: str, language: str = DEFAULT_LANGUAGE) -> str:
        """The label of ``iri`` in ``language``, else in the default language, else its local name in words."""
        for lang in (language.lower(), DEFAULT_LANGUAGE):
            if (iri, lang) in self._labels:
                return self._labels[(iri, lang)]
        if iri in self._fallback:
            return self._fallback[iri]
        return re.sub(r"(?<=[a-z0-9])(?=[A-Z])", " ", local_name(iri)).lower()

    def languages(self) -> list[str]:
        """The language tags some label is given in."""
        return sorted({lang for _, lang in self._labels})


class Ontology:
    """The asserted axioms of the TBox files, indexed for justification search, and their labels."""

    def __init__(self, axioms: Iterable[Axiom], labels: Labels):
        self.axioms = tuple(a for a in axioms if a.kind != "defined")
        self.definitions = tuple(a for a in axioms if a.kind == "defined")
        self.labels = labels
        self._out: dict[str, list[Axiom]] = {}
        for a in self.axioms:
            self._out.setdefault(a.sub, []).append(a)
            if a.kind == "equivalent":
                self._out.setdefault(a.sup, []).append(Axiom("equivalent", a.sup, a.sub, a.where))

    def subsumption(self, sub: str, sup: str, taxonomy: Taxonomy) -> tuple[Axiom, ...] | None:
        """The shortest chain of named subclass/equivalence axioms entailing ``sub ⊑ sup`` (empty when equal),
        or None when the reasoner does not derive it or no such chain is asserted."""
        if not taxonomy.is_a(sub, sup):
            return None
        if sub == sup:
            return ()
        return self._named(sub, sup) or self._by_definition(sub, sup, taxonomy)

    def _named(self, sub: str, sup: str) -> tuple[Axiom, ...] | None:
        """The shortest chain of named subclass/equivalence axioms from ``sub`` up to ``sup``."""
        return () if sub == sup else self._search(sub, lambda a, _: a.kind in ("subclass", "equivalent"), (sup, 0))

    def _by_definition(self, sub: str, sup: str, taxonomy: Taxonomy) -> tuple[Axiom, ...] | None:
        """``sub ⊑ sup`` through a definition ``D ≡ C1 ⊓ ∃p.C2 …`` with ``D ⊑ sup``: ``sub`` meets every conjunct."""
        for d in self.definitions:
            if not (taxonomy.is_a(sub, d.sub) and taxonomy.is_a(d.sub, sup)) or sub == d.sub:
                continue
            chain: list[Axiom] = []
            for prop, cls in d.parts:
                part = self._some(sub, prop, cls, taxonomy) if prop else self._named(sub, cls)
                if part is None:
                    break
                chain += part
            else:
                tail = self._named(d.sub, sup)
                if tail is not None:
                    return tuple(dict.fromkeys([*chain, d, *tail]))
        return None

    def _some(self, sub: str, prop: str, cls: str, taxonomy: Taxonomy) -> tuple[Axiom, ...] | None:
        """The shortest chain ``sub ⊑ … ⊑ X``, ``X ⊑ ∃prop.F``, ``F ⊑ … ⊑ cls`` of asserted axioms."""
        best: tuple[Axiom, ...] | None = None
        for a in self.axioms:
            if a.prop != prop or not (taxonomy.is_a(sub, a.sub) and taxonomy.is_a(a.sup, cls)):
                continue
            up, down = self._named(sub, a.sub), self._named(a.sup, cls)
            if up is not None and down is not None and (best is None or len(up) + len(down) + 1 < len(best)):
                best = (*up, a, *down)
        return best

    def implied_skill(self, cls: str, skill: str, taxonomy: Taxonomy) -> tuple[Axiom, ...] | None:
        """The shortest chain ``cls ⊑ … ⊑ ∃hasSkill.S1``, ``S1 ⊑ … ⊑ skill``, when the reasoner derives that a
        device of class ``cls`` has ``skill``."""
        if skill not in taxonomy.implied_skills.get(cls, frozenset()):
            return None
        return self._search(cls, lambda a, phase: a.kind in ("subclass", "equivalent")
                            or (a.kind == "has_skill" and phase == 0), (skill, 1))

    def _search(self, start: str, usable: Callable[[Axiom, int], bool],
                goal: tuple[str, int]) -> tuple[Axiom, ...] | None:
        """Breadth first over (class, phase): phase 0 walks the start's superclasses, phase 1 (after a
        ``∃hasSkill`` restriction) walks skills."""
        seen = {(start, 0)}
        queue: deque[tuple[tuple[str, int], tuple[Axiom, ...]]] = deque([((start, 0), ())])
        while queue:
            (iri, phase), chain = queue.popleft()
            for a in self._out.get(iri, []):
                if not usable(a, phase):
                    continue
                nxt = (a.sup, 1 if a.kind == "has_skill" else phase)
                if nxt == goal:
                    return (*chain, a)
                if nxt not in seen:
                    seen.add(nxt)
                    queue.append((nxt, (*chain, a)))
        return None


def _curies(g: rdflib.Graph, iri: str) -> list[str]:
    out = [f"<{iri}>"]
    for prefix, ns in g.namespaces():
        if prefix and iri.startswith(str(ns)):
            out.append(f"{prefix}:{iri[len(str(ns)):]}")
    return out


def _line(lines: list[str], g: rdflib.Graph, subject: str, obj: str) -> int | None:
    """The line of the statement about ``subject`` that names ``obj`` (or the subject's first line)."""
    start = re.compile(r"^\s*(" + "|".join(re.escape(c) for c in _curies(g, subject)) + r")(\s|$)")
    named = re.compile("|".join(re.escape(c) + r"(?![\w-])" for c in _curies(g, obj)))
    for n, text in enumerate(lines):
        if not start.match(text):
            continue
        for m in range(n, len(lines)):
            if named.search(lines[m] if m > n else lines[m][start.match(text).end():]):  # type: ignore[union-attr]
                return m + 1
            if lines[m].rstrip().endswith(" ."):
                break
        return n + 1
    return None


def _file_axioms(path: Path) -> tuple[list[Axiom], rdflib.Graph]:
    tbox = read_tbox_file(path)
    g, tree = tbox.graph, tbox.tree
    lines = tbox.text.splitlines()
    out: list[Axiom] = []

    def where(kind: str, s: str, o: str) -> Where:
        return Where(str(path), _line(lines, g, s, o) if tree is None else axiom_line(tree, path, kind, s, o))

    for s, o in g.subject_objects(RDFS.subClassOf):
        if not isinstance(s, rdflib.URIRef):
            continue
        if isinstance(o, rdflib.URIRef):
            out.append(Axiom("subclass", str(s), str(o), where("subclass", str(s), str(o))))
        elif (some := _some_of(g, o)) is not None:
            prop, filler = some
            kind = "has_skill" if prop == str(PNP.hasSkill) else "some"
            out.append(Axiom(kind, str(s), filler, where("has_skill" if kind == "has_skill" else "some", str(s),
                                                         filler), prop))
    for s, o in g.subject_objects(OWL.equivalentClass):
        if isinstance(s, rdflib.URIRef) and isinstance(o, rdflib.URIRef):
            out.append(Axiom("equivalent", str(s), str(o), where("equivalent", str(s), str(o))))
        elif isinstance(s, rdflib.URIRef) and (parts := _conjuncts(g, o)):
            out += _definition(str(s), parts, where("defined", str(s), next(c for _, c in parts)))
    return out, g


def _some_of(g: rdflib.Graph, node: rdflib.term.Node) -> tuple[str, str] | None:
    """``(property, filler)`` of a restriction ``∃property.filler`` with a named property and filler."""
    prop, filler = g.value(node, OWL.onProperty), g.value(node, OWL.someValuesFrom)
    if isinstance(prop, rdflib.URIRef) and isinstance(filler, rdflib.URIRef):
        return str(prop), str(filler)
    return None


def _conjuncts(g: rdflib.Graph, node: rdflib.term.Node) -> tuple[tuple[str, str], ...]:
    """The conjuncts of ``C1 ⊓ ∃p.C2 ⊓ …`` as (property or "", class); nothing if one is of another form."""
    head = g.value(node, OWL.intersectionOf)
    if head is None:
        return ()
    parts: list[tuple[str, str]] = []
    for item in rdflib.collection.Collection(g, head):
        some = None if isinstance(item, rdflib.URIRef) else _some_of(g, item)
        if isinstance(item, rdflib.URIRef):
            parts.append(("", str(item)))
        elif some is not None:
            parts.append(some)
        else:
            return ()
    return tuple(parts)


def _definition(cls: str, parts: tuple[tuple[str, str], ...], where: Where) -> list[Axiom]:
    """The definition ``cls ≡ parts`` and the axioms it entails (``cls ⊑`` each conjunct), shown as it."""
    d = Axiom("defined", cls, parts[0][1], where, parts=parts)
    entailed = [Axiom("subclass" if not p else "has_skill" if p == str(PNP.hasSkill) else "some", cls, c, where, p,
                      shown=d.formula()) for p, c in parts]
    return [d, *entailed]


def load_ontology(files: Iterable[Path], taxonomy: Taxonomy) -> Ontology:
    """The asserted axioms and labels of the TBox ``files`` (labels the files lack come from ``taxonomy``)."""
    axioms: list[Axiom] = []
    graph = rdflib.Graph()
    for path in files:
        found, g = _file_axioms(path)
        axioms += found
        graph += g
    return Ontology(sorted(axioms, key=lambda a: (a.where.file, a.where.line or 0)),
                    Labels.from_graph(graph, taxonomy.labels))


_LOADED: dict[tuple[tuple[str, ...], str], Ontology] = {}


def ontology_of(files: Iterable[Path], taxonomy: Taxonomy) -> Ontology:
    """:func:`load_ontology`, read once per set of files and closure (the TBox does not change while it runs)."""
    key = (tuple(str(f) for f in files), taxonomy.digest)
    if key not in _LOADED:
        _LOADED[key] = load_ontology([Path(f) for f in key[0]], taxonomy)
    return _LOADED[key]
