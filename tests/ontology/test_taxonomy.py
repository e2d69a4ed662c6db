"""The taxonomy closure: facts only DL classification yields, consistency, caching."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from plugnproduce.errors import OntologyError
from plugnproduce.ontology import taxonomy as taxonomy_module
from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy, ontology_files

P = "http://plugnproduce.org/ontology#"


def test_device_class_is_classified_by_its_skill(taxonomy: Taxonomy) -> None:
    # ParallelGripper ⊑ ∃hasSkill.CanParallelGrip and CanParallelGrip ⊑ CanGrip: only the
    # reasoner concludes that a ParallelGripper is a GrippingDevice (≡ Device ⊓ ∃hasSkill.CanGrip).
    assert taxonomy.is_a(P + "ParallelGripper", P + "GrippingDevice")
    assert taxonomy.is_a(P + "VacuumGripper", P + "GrippingDevice")
    assert not taxonomy.is_a(P + "Screwdriver", P + "GrippingDevice")


def test_skill_implied_by_class(taxonomy: Taxonomy) -> None:
    assert taxonomy.implied_skills[P + "BinPickingPC"] == {P + "CanLocalizeParts"}
    assert {P + "CanMoveArm", P + "CanMove"} <= taxonomy.implied_skills[P + "CollaborativeRobot"]


def test_state_concept_subsumed_through_equivalence(taxonomy: Taxonomy) -> None:
    assert taxonomy.is_a(P + "Released", P + "Open")
    assert taxonomy.is_a(P + "Open", P + "Released")
    # ClosedWithPart ⊑ ∃holds.Part and GripperState, so it is a HoldingPart (a defined class).
    assert taxonomy.is_a(P + "ClosedWithPart", P + "HoldingPart")
    assert not taxonomy.is_a(P + "ClosedEmpty", P + "HoldingPart")


def test_mandatory_states_are_inherited_from_super_skills(taxonomy: Taxonomy) -> None:
    assert taxonomy.mandatory_states[P + "CanSuctionGrip"] == {P + "Open", P + "Closed"}


def test_closure_is_cached_by_content(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    first = load_taxonomy(cache_dir=tmp_path)

    def no_reasoner(*_: object) -> Taxonomy:
        raise AssertionError("the reasoner ran although the ontology did not change")

    monkeypatch.setattr(taxonomy_module, "classify", no_reasoner)
    assert load_taxonomy(cache_dir=tmp_path) == first


def test_changed_ontology_is_reasoned_again(tmp_path: Path) -> None:
    folder = tmp_path / "onto"
    folder.mkdir()
    for f in ontology_files():
        shutil.copy(f, folder)
    extra = folder / "extension.ttl"
    extra.write_text(
        "@prefix pnp: <http://plugnproduce.org/ontology#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
        "pnp:SoftGripper a owl:Class ; rdfs:subClassOf pnp:ParallelGripper .\n"
    )
    t = load_taxonomy(ontology_files(folder), cache_dir=tmp_path)
    assert t.is_a(P + "SoftGripper", P + "GrippingDevice")
    assert P + "CanGrip" in t.implied_skills[P + "SoftGripper"]


def test_inconsistent_ontology_is_an_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.ttl"
    shutil.copy(ontology_files()[0], bad)
    with bad.open("a") as f:
        # A class below two disjoint classes, with a member: HermiT finds the contradiction.
        f.write("\npnp:Impossible a owl:Class ; rdfs:subClassOf pnp:Open , pnp:Closed .\n"
                "pnp:someState a pnp:Impossible .\n")
    with pytest.raises(OntologyError, match="inconsistent"):
        load_taxonomy([bad], use_cache=False)
