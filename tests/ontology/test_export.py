"""``pnp ontology export``: the merged TBox for Protégé, opened here by owlready2 as Protégé would open it."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import owlready2
import pytest
import rdflib
from rdflib.namespace import OWL, RDFS
from typer.testing import CliRunner

from plugnproduce.cli import app
from tests.knowledge.test_libraries import TF, THREE_FINGER

runner = CliRunner()
PNP = "http://plugnproduce.org/ontology#"
KINDS = {"device_classes": "Device", "skills": "Skill", "state_concepts": "StateConcept", "quantities": "Quantity",
         "outcomes": "Outcome"}
MERGED = "http://plugnproduce.org/ontology/merged"


def export(tmp_path: Path, fmt: str, *more: str) -> Path:
    out = tmp_path / f"merged.{fmt}"
    result = runner.invoke(app, ["--library", str(THREE_FINGER), "ontology", "export", "-o", str(out),
                                 "--format", fmt, *more])
    assert result.exit_code == 0, result.output
    return out


def open_in_owlready2(path: Path, fmt: str) -> Any:
    world = owlready2.World()
    if fmt == "turtle":  # owlready2 reads no Turtle: through N-Triples, as its documentation says
        data, fmt = rdflib.Graph().parse(path, format="turtle").serialize(format="nt", encoding="utf-8"), "ntriples"
    else:
        data = path.read_bytes()
    world.get_ontology(MERGED).load(fileobj=io.BytesIO(data), format=fmt)
    return world


def vocab_closure() -> dict[str, dict[str, set[str]]]:
    """Per kind, each class → its ancestors of that kind (itself and its equivalents included), from pnp vocab."""
    doc = json.loads(runner.invoke(app, ["--library", str(THREE_FINGER), "vocab", "--json"]).stdout)
    out: dict[str, dict[str, set[str]]] = {}
    for kind, root in KINDS.items():
        up = {e["iri"]: {_iri(p) for p in e["parents"] + e["equivalent"]} for e in doc[kind]}
        up[PNP + root] = set()
        closure = {}
        for c in up:
            seen, todo = {c}, [c]
            while todo:
                for p in up.get(todo.pop(), ()):
                    if p not in seen:
                        seen.add(p)
                        todo.append(p)
            closure[c] = seen
        out[kind] = closure
    return out


def _iri(name: str) -> str:
    return PNP + name[4:] if name.startswith("pnp:") else name


@pytest.mark.parametrize("fmt", ["rdfxml", "turtle", "owlxml"])
def test_the_inferred_export_opens_in_owlready2_with_the_hierarchy_of_pnp_vocab(tmp_path: Path, fmt: str) -> None:
    world = open_in_owlready2(export(tmp_path, fmt, "--inferred"), fmt)
    for kind, closure in vocab_closure().items():
        root = world[PNP + KINDS[kind]]
        below = {c.iri for c in root.descendants()}
        assert below == set(closure), kind  # the same classes, as many
        for iri, ancestors in closure.items():  # asserted in the file: no reasoner runs here
            named = {a.iri for a in world[iri].ancestors() if isinstance(a, owlready2.ThingClass)}
            assert named & below == ancestors, iri
    assert TF + "ThreeFingerGripper" in {c.iri for c in world[PNP + "Device"].descendants()}


def test_the_inferred_axioms_are_marked_as_the_reasoner_s(tmp_path: Path) -> None:
    plain = rdflib.Graph().parse(export(tmp_path, "turtle"), format="turtle")
    derived = rdflib.Graph().parse(export(tmp_path, "turtle", "--inferred"), format="turtle")
    magnetic, gripping = rdflib.URIRef(PNP + "MagneticGripper"), rdflib.URIRef(PNP + "GrippingDevice")
    assert (magnetic, RDFS.subClassOf, gripping) not in plain  # HermiT derives it from a defined class
    assert (magnetic, RDFS.subClassOf, gripping) in derived
    marks = [a for a in derived.subjects(OWL.annotatedSource, magnetic)
             if derived.value(a, OWL.annotatedTarget) == gripping]
    assert [str(derived.value(m, rdflib.URIRef(PNP + "inferredBy"))) for m in marks] == ["HermiT"]
    asserted = rdflib.URIRef(PNP + "ParallelGripper"), RDFS.subClassOf, rdflib.URIRef(PNP + "Gripper")
    assert asserted in plain and asserted[2] not in {derived.value(a, OWL.annotatedTarget)
                                                     for a in derived.subjects(OWL.annotatedSource, asserted[0])}
    assert list(plain.subjects(rdflib.RDF.type, OWL.Ontology)) == [rdflib.URIRef(MERGED)]
    assert not list(plain.objects(None, OWL.imports))


def test_the_asserted_export_in_owlxml_keeps_the_library_axioms(tmp_path: Path) -> None:
    world = open_in_owlready2(export(tmp_path, "owlxml"), "owlxml")
    three = world[TF + "ThreeFingerGripper"]
    assert world[PNP + "Gripper"] in three.is_a
    assert world[PNP + "GrippingDevice"] not in three.is_a


def test_an_unknown_format_is_one_line() -> None:
    result = runner.invoke(app, ["ontology", "export", "--format", "obo"])
    assert result.exit_code == 2
    assert result.stderr == "--format 'obo': expected one of rdfxml, turtle, owlxml\n"
