"""The taxonomy closure: what the DL reasoner (HermiT through owlready2) derives from the TBox.

The closure is computed once per ontology content and cached on disk by its SHA-256,
because HermiT costs a JVM start per call. Everything downstream (SHACL, ASP facts,
code generation) asks this object, never the reasoner.
"""

from __future__ import annotations

import io
import json
from collections.abc import Iterable
from dataclasses import field
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.deferred import dataclass
from plugnproduce.digests import sha256
from plugnproduce.errors import OntologyError
from plugnproduce.folders import cache_folder
from plugnproduce.ontology.iris import PNP_IRI, local_name
from plugnproduce.ontology.sources import folder_files
from plugnproduce.resources import ontology_path

if TYPE_CHECKING:  # reading and classifying a TBox needs rdflib; the closure read back from a cache does not
    import rdflib

CACHE_VERSION = 2
_CAPABILITY_PREFIX = PNP_IRI + "_HasSkill_"
ROOTS = ("Device", "Skill", "StateConcept", "Process", "Quantity")


@dataclass(frozen=True)
class Taxonomy:
    """Class subsumption, implied skills and mandatory states of the ontology."""

    digest: str
    superclasses: dict[str, frozenset[str]]
    """Every named class → its named superclasses and equivalents, itself included."""
    implied_skills: dict[str, frozenset[str]]
    """Device class → every skill a device of that class has (super-skills included)."""
    mandatory_states: dict[str, frozenset[str]]
    """Skill → state concepts a device with that skill must have (own and inherited)."""
    labels: dict[str, str] = field(default_factory=dict)

    def is_a(self, sub: str, sup: str) -> bool:
        """Whether class ``sub`` is subsumed by ``sup`` (reflexive)."""
        return sup in self.superclasses.get(sub, frozenset((sub,)))

    def knows(self, iri: str) -> bool:
        """Whether ``iri`` is a named class of the ontology."""
        return iri in self.superclasses

    def is_kind(self, iri: str, root: str) -> bool:
        """Whether ``iri`` is a class under one of :data:`ROOTS` (e.g. ``"Skill"``)."""
        return self.is_a(iri, PNP_IRI + root) and iri != PNP_IRI + root

    def classes_of_kind(self, root: str) -> list[str]:
        """All named classes under ``root``, sorted."""
        return sorted(c for c in self.superclasses if self.is_kind(c, root))

    def skill_closure(self, skills: Iterable[str]) -> frozenset[str]:
        """The given skills and every skill subsuming them."""
        out: set[str] = set()
        for s in skills:
            out |= {c for c in self.superclasses.get(s, {s}) if self.is_kind(c, "Skill")}
        return frozenset(out)

    def device_skills(self, device_classes: Iterable[str], declared: Iterable[str]) -> frozenset[str]:
        """Skills of a device: declared ones, those its classes imply, and their super-skills."""
        implied: set[str] = set(declared)
        for c in device_classes:
            implied |= self.implied_skills.get(c, frozenset())
        return self.skill_closure(implied)

    def label(self, iri: str) -> str:
        """The human label of a term, or its local name."""
        return self.labels.get(iri, local_name(iri))

    def to_json(self) -> str:
        """Serialise for the on-disk cache."""
        return json.dumps(
            {
                "version": CACHE_VERSION,
                "digest": self.digest,
                "superclasses": {k: sorted(v) for k, v in sorted(self.superclasses.items())},
                "implied_skills": {k: sorted(v) for k, v in sorted(self.implied_skills.items())},
                "mandatory_states": {k: sorted(v) for k, v in sorted(self.mandatory_states.items())},
                "labels": dict(sorted(self.labels.items())),
            },
            indent=1,
        )

    @classmethod
    def from_json(cls, text: str) -> Taxonomy:
        """Read back what :meth:`to_json` wrote."""
        d = json.loads(text)
        if d.get("version") != CACHE_VERSION:
            raise ValueError("cache version differs")

        def sets(m: dict[str, list[str]]) -> dict[str, frozenset[str]]:
            return {k: frozenset(v) for k, v in m.items()}

        return cls(
            d["digest"],
            sets(d["superclasses"]),
            sets(d["implied_skills"]),
            sets(d["mandatory_states"]),
            d["labels"],
        )


def ontology_files(folder: Path | None = None) -> list[Path]:
    """The TBox files of an ontology folder: Turtle, RDF/XML and OWL/XML, except the SHACL shapes."""
    return folder_files(folder or ontology_path())


def read_tbox(files: Iterable[Path]) -> rdflib.Graph:
    """Parse the TBox files (any of the three formats) into one graph, with ``file: message`` errors."""
    import rdflib

    from plugnproduce.ontology.sources import read_tbox_file

    g = rdflib.Graph()
    for p in files:
        g += read_tbox_file(p).graph
    return g


def _digest(files: Iterable[Path]) -> str:
    """The cache key of a TBox: every file's name and bytes, in order. The format is told by the bytes
    (see :mod:`~plugnproduce.ontology.sources`), so the same TBox saved as Turtle, RDF/XML or OWL/XML has three
    keys; imported files are among ``files`` (the libraries list them), so editing one reclassifies."""
    from plugnproduce.safeio import read_bytes

    h = sha256()
    for p in files:
        h.update(p.name.encode() + b"\0" + read_bytes(p) + b"\0")
    return h.hexdigest()


def default_cache_dir() -> Path:
    """Where closures are cached: the user's cache folder (``$XDG_CACHE_HOME/plugnproduce`` when set), as every
    other kept result (:func:`plugnproduce.folders.cache_folder`)."""
    return cache_folder()


def load_taxonomy(
    files: Iterable[Path] | None = None, cache_dir: Path | None = None, use_cache: bool = True
) -> Taxonomy:
    """The taxonomy closure of the ontology, from the cache or from HermiT."""
    paths = list(files) if files is not None else ontology_files()
    digest = _digest(paths)
    shipped = shipped_closure(digest)
    if shipped is not None:
        return shipped
    cache = (cache_dir or default_cache_dir()) / f"taxonomy-{digest[:32]}.json"
    if use_cache and cache.is_file():
        try:
            return Taxonomy.from_json(cache.read_text())
        except (ValueError, KeyError):
            pass  # stale or damaged cache: recompute
    taxonomy = classify(read_tbox(paths), digest)
    if use_cache:
        try:
            cache.parent.mkdir(parents=True, exist_ok=True)
            tmp = cache.with_suffix(".tmp")
            tmp.write_text(taxonomy.to_json())
            tmp.replace(cache)
        except OSError:
            pass  # a read-only home only costs the next run a reasoner call
    return taxonomy


SHIPPED_CLOSURE = "closure.json"
"""The built-in ontology's closure, computed once and shipped beside it (see :func:`ship_closure`)."""


def shipped_closure(digest: str) -> Taxonomy | None:
    """The shipped closure if it was computed from content with this ``digest``, else None."""
    path = ontology_path() / SHIPPED_CLOSURE
    try:
        taxonomy = Taxonomy.from_json(path.read_text())
    except (OSError, ValueError, KeyError):
        return None
    return taxonomy if taxonomy.digest == digest else None


def ship_closure(folder: Path | None = None) -> Path:
    """Classify the built-in ontology with HermiT and write its closure beside it (a build step)."""
    folder = folder or ontology_path()
    files = ontology_files(folder)
    path = folder / SHIPPED_CLOSURE
    path.write_text(classify(read_tbox(files), _digest(files)).to_json() + "\n")
    return path


def _named_subclasses(g: rdflib.Graph, root: rdflib.URIRef) -> set[str]:
    import rdflib
    from rdflib.namespace import RDFS

    return {str(c) for c in g.transitive_subjects(RDFS.subClassOf, root) if isinstance(c, rdflib.URIRef)}


def classify(g: rdflib.Graph, digest: str = "") -> Taxonomy:
    """Run HermiT on the TBox ``g`` and read off the closure."""
    import owlready2
    import rdflib
    from rdflib.namespace import OWL, RDF

    from plugnproduce.ontology.vocabulary import PNP

    skills = sorted(_named_subclasses(g, PNP.Skill) - {str(PNP.Skill)})
    cap = rdflib.Graph()
    for n, s in enumerate(skills):  # _HasSkill_n ≡ Device ⊓ ∃hasSkill.S reveals implied skills
        c, r, i = rdflib.URIRef(f"{_CAPABILITY_PREFIX}{n}"), rdflib.BNode(), rdflib.BNode()
        cap.add((c, RDF.type, OWL.Class))
        cap.add((r, RDF.type, OWL.Restriction))
        cap.add((r, OWL.onProperty, PNP.hasSkill))
        cap.add((r, OWL.someValuesFrom, rdflib.URIRef(s)))
        lst = rdflib.BNode()
        rdflib.collection.Collection(cap, lst, [PNP.Device, r])
        cap.add((i, RDF.type, OWL.Class))
        cap.add((i, OWL.intersectionOf, lst))
        cap.add((c, OWL.equivalentClass, i))
    merged = g + cap
    merged.remove((None, OWL.imports, None))  # the files are merged already; owlready2 would fetch imports
    nt = merged.serialize(format="nt", encoding="utf-8")
    import tempfile  # only reasoning needs a folder of its own: a closure read back needs none

    world = owlready2.World()
    try:
        onto = world.get_ontology(PNP_IRI.rstrip("#")).load(fileobj=io.BytesIO(nt), format="ntriples")
        with tempfile.TemporaryDirectory(prefix="pnp-hermit-") as tmp:
            saved, tempfile.tempdir = tempfile.tempdir, tmp
            try:
                with onto:
                    owlready2.sync_reasoner_hermit(world, infer_property_values=False, debug=0)
            finally:
                tempfile.tempdir = saved
    except owlready2.OwlReadyInconsistentOntologyError as exc:
        raise OntologyError("the ontology is inconsistent (HermiT)") from exc
    except owlready2.OwlReadyJavaError as exc:
        raise OntologyError(f"HermiT failed: {str(exc).splitlines()[0]}") from exc
    return _read_closure(world, g, skills, digest)


def _read_closure(world: object, g: rdflib.Graph, skills: list[str], digest: str) -> Taxonomy:
    import owlready2
    import rdflib
    from rdflib.namespace import OWL, RDFS

    from plugnproduce.ontology.vocabulary import PNP

    superclasses: dict[str, frozenset[str]] = {}
    implied: dict[str, frozenset[str]] = {}
    for cls in world.classes():  # type: ignore[attr-defined]
        iri = cls.iri
        if iri.startswith(_CAPABILITY_PREFIX):
            continue
        named = {a.iri for a in cls.ancestors() if isinstance(a, owlready2.ThingClass)}
        named |= {e.iri for e in cls.equivalent_to if isinstance(e, owlready2.ThingClass)}
        named.discard(str(OWL.Thing))
        caps = {skills[int(a[len(_CAPABILITY_PREFIX):])] for a in named if a.startswith(_CAPABILITY_PREFIX)}
        superclasses[iri] = frozenset(a for a in named if not a.startswith(_CAPABILITY_PREFIX))
        if caps and iri != str(PNP.Device):
            implied[iri] = frozenset(caps)
    mandatory: dict[str, frozenset[str]] = {}
    for s in skills:
        states = {
            str(m) for sup in superclasses.get(s, {s}) for m in g.objects(rdflib.URIRef(sup), PNP.mandatoryState)
        }
        if states:
            mandatory[s] = frozenset(states)
    labels = {str(s): str(o) for s, o in g.subject_objects(RDFS.label) if isinstance(s, rdflib.URIRef)}
    return Taxonomy(digest, superclasses, implied, mandatory, labels)


if __name__ == "__main__":  # python -m plugnproduce.ontology.taxonomy: refresh the shipped closure
    print(ship_closure())
