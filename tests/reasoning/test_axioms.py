"""OWL evidence: asserted axioms with their lines, minimal justifications, labels by language; rule lookup."""

from __future__ import annotations

from pathlib import Path

import rdflib

from plugnproduce import service
from plugnproduce.reasoning.asp.derivation import rule
from plugnproduce.reasoning.explanation.axioms import Labels, load_ontology

PNP = "http://plugnproduce.org/ontology#"


def test_the_shortest_chain_of_asserted_axioms_justifies_an_implied_skill() -> None:
    k = service.knowledge()
    onto = load_ontology(k.ontology_files(), k.taxonomy)
    chain = onto.implied_skill(PNP + "CollaborativeRobot", PNP + "CanMove", k.taxonomy)
    assert chain is not None
    assert [a.formula() for a in chain] == ["CollaborativeRobot ⊑ ArticulatedRobot",
                                            "ArticulatedRobot ⊑ IndustrialRobot",
                                            "IndustrialRobot ⊑ ∃hasSkill.CanMoveArm", "CanMoveArm ⊑ CanMove"]
    for a in chain:
        line = Path(a.where.file).read_text(encoding="utf-8").splitlines()[(a.where.line or 0) - 1]
        assert a.sup.rsplit("#", 1)[1] in line


def test_no_justification_for_what_the_reasoner_does_not_derive() -> None:
    k = service.knowledge()
    onto = load_ontology(k.ontology_files(), k.taxonomy)
    assert onto.implied_skill(PNP + "Camera", PNP + "CanGrip", k.taxonomy) is None
    assert onto.subsumption(PNP + "Closed", PNP + "Open", k.taxonomy) is None
    assert onto.subsumption(PNP + "Open", PNP + "Open", k.taxonomy) == ()


def test_an_equivalence_justifies_both_ways() -> None:
    k = service.knowledge()
    onto = load_ontology(k.ontology_files(), k.taxonomy)
    chain = onto.subsumption(PNP + "Released", PNP + "GripperState", k.taxonomy)
    assert chain is not None and [a.formula() for a in chain] == ["Released ≡ Open", "Open ⊑ GripperState"]


def test_labels_by_language_fall_back_to_english_then_to_words() -> None:
    g = rdflib.Graph()
    g.parse(data='@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> . '
                 '<http://x/A> rdfs:label "gripper" , "Greifer"@de . <http://x/B> rdfs:label "open"@en .',
            format="turtle")
    labels = Labels.from_graph(g)
    assert (labels.label("http://x/A", "de"), labels.label("http://x/A"), labels.label("http://x/B", "de")) == (
        "Greifer", "gripper", "open")
    assert labels.label("http://x#ClosedWithPart") == "closed with part"
    assert labels.languages() == ["de", "en"]


def test_a_rule_is_found_at_its_line_and_instantiated() -> None:
    r = rule("offered.lp", "fillable")
    assert r.where().line == r.line and r.text.startswith("fillable(C,P,R) :-")
    assert r.instance({"C": "cell", "P": "pick", "R": "gripper", "D": "gripper"}) == (
        'fillable("cell","pick","gripper") :- member("cell","gripper"), can_play("pick","gripper","gripper").')
    assert rule("roles.lp", "walk", 1).instance({"I": 1}).startswith("walk(P,R,D,2,Y)")


def test_a_subsumption_through_a_definition_names_every_asserted_axiom_it_comes_from() -> None:
    # ClosedWithPart ⊑ HoldingPart: no chain of subclass axioms states it; HermiT derives it from the
    # definition HoldingPart ≡ GripperState ⊓ ∃holds.Part, which ClosedWithPart meets.
    k = service.knowledge()
    onto = load_ontology(k.ontology_files(), k.taxonomy)
    chain = onto.subsumption(PNP + "ClosedWithPart", PNP + "HoldingPart", k.taxonomy)
    assert chain is not None
    assert [a.formula() for a in chain] == ["ClosedWithPart ⊑ Closed", "Closed ⊑ GripperState",
                                            "ClosedWithPart ⊑ ∃holds.Part", "HoldingPart ≡ GripperState ⊓ ∃holds.Part"]
    for a in chain:
        line = Path(a.where.file).read_text(encoding="utf-8").splitlines()[(a.where.line or 0) - 1]
        assert a.sup.rsplit("#", 1)[1] in line


def test_a_class_under_a_defined_class_has_its_skill_justified_by_the_definition(tmp_path: Path) -> None:
    lib = tmp_path / "lib"
    (lib / "ontology").mkdir(parents=True)
    (lib / "ontology" / "grabber.ttl").write_text(
        "@prefix pnp: <http://plugnproduce.org/ontology#> .\n@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n<http://example.org/g> a owl:Ontology .\n"
        "<http://example.org/g#Grabber> a owl:Class ;\n    rdfs:subClassOf pnp:GrippingDevice .\n")
    k = service.knowledge((lib,))
    onto = load_ontology(k.ontology_files(), k.taxonomy)
    chain = onto.implied_skill("http://example.org/g#Grabber", PNP + "CanGrip", k.taxonomy)
    assert chain is not None
    assert [a.formula() for a in chain] == ["Grabber ⊑ GrippingDevice", "GrippingDevice ≡ Device ⊓ ∃hasSkill.CanGrip"]
    pnp_ttl = Path(chain[1].where.file).read_text(encoding="utf-8").splitlines()
    defined = 1 + next(i for i, line in enumerate(pnp_ttl) if line.startswith("pnp:GrippingDevice a owl:Class"))
    assert [(Path(a.where.file).name, a.where.line) for a in chain] == [("grabber.ttl", 6), ("pnp.ttl", defined + 1)]
    assert "owl:equivalentClass" in pnp_ttl[defined]  # the line of the definition itself
