"""Protégé's formats in libraries: RDF/XML and OWL/XML TBox files, and owl:imports through a catalog."""

from __future__ import annotations

import io
import json
import random
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, cast

import owlready2
import pyhornedowl
import pytest
import rdflib
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.sources import read_tbox_file
from plugnproduce.ontology.taxonomy import classify, load_taxonomy, read_tbox
from plugnproduce.reasoning.explanation.axioms import Axiom, load_ontology
from plugnproduce.resources import ontology_path

runner = CliRunner()
BUILTIN = service.builtin()
LAB = Path(__file__).parents[1] / "data" / "libraries" / "protege-lab"
SKILLS_IRI = "http://example.org/protege-lab/skills"


def save_as_rdfxml(turtle: Path, target: Path) -> Path:
    """What an engineer gets from owlready2's ``save()``: the Turtle TBox in RDF/XML."""
    nt = rdflib.Graph().parse(turtle).serialize(format="nt", encoding="utf-8")
    world = owlready2.World()
    onto = world.get_ontology("http://plugnproduce.org/ontology").load(fileobj=io.BytesIO(nt), format="ntriples")
    onto.save(file=str(target), format="rdfxml")
    world.close()
    return target


def line_of(path: Path, text: str) -> int:
    """The number of the first line holding ``text``."""
    return next(n for n, x in enumerate(path.read_text().splitlines(), 1) if text in x)


def test_the_builtin_ontology_saved_as_rdfxml_classifies_the_same(tmp_path: Path) -> None:
    owl = save_as_rdfxml(ontology_path() / "pnp.ttl", tmp_path / "pnp.owl")
    assert owl.read_text().lstrip().startswith("<?xml")
    again, builtin = classify(read_tbox([owl])), load_taxonomy()
    assert again.superclasses == builtin.superclasses
    assert again.implied_skills == builtin.implied_skills
    assert again.mandatory_states == builtin.mandatory_states


def test_a_library_of_the_builtin_ontology_in_rdfxml_offers_the_same_commands(tmp_path: Path) -> None:
    lib = tmp_path / "lib"
    for kind in ("devices", "processes", "cells"):
        shutil.copytree(BUILTIN / kind, lib / kind)
    (lib / "ontology").mkdir()
    save_as_rdfxml(ontology_path() / "pnp.ttl", lib / "ontology" / "pnp.owl")
    ours = runner.invoke(app, ["--no-builtin", "--library", str(lib), "capabilities", "--json",
                               "--cell", str(lib / "cells" / "bin-picking.yaml")])
    theirs = runner.invoke(app, ["capabilities", "--json", "--cell", str(BUILTIN / "cells" / "bin-picking.yaml")])
    assert ours.exit_code == 0, ours.output
    offered = [{k: o[k] for k in ("command", "bindings")} for o in json.loads(ours.stdout)["offered"]]
    assert offered == [{k: o[k] for k in ("command", "bindings")} for o in json.loads(theirs.stdout)["offered"]]
    vocab = json.loads(runner.invoke(app, ["--no-builtin", "--library", str(lib), "vocab", "--json"]).stdout)
    assert vocab["device_classes"] == json.loads(runner.invoke(app, ["vocab", "--json"]).stdout)["device_classes"]


def test_an_rdfxml_library_with_a_catalog_import_offers_its_commands() -> None:
    result = runner.invoke(app, ["--library", str(LAB), "capabilities", "--json",
                                 "--cell", str(LAB / "cells" / "bin-picking-soft.yaml")])
    assert result.exit_code == 0, result.output
    offered = {o["command"]: o["bindings"] for o in json.loads(result.stdout)["offered"]}
    assert {"gripper": "soft-gripper", "robot": "robot"} in offered["pick"]


def test_explanations_cite_rdfxml_and_owlxml_axioms_at_their_element_lines() -> None:
    result = runner.invoke(app, ["--library", str(LAB), "explain", "--verbose", "pick",
                                 "--cell", str(LAB / "cells" / "bin-picking-soft.yaml")])
    assert result.exit_code == 0, result.output
    owl, owx = LAB / "ontology" / "lab.owl", LAB / "ontology" / "imports" / "skills.owx"
    restriction = max(n for n, x in enumerate(owl.read_text().splitlines(), 1)
                      if "<rdfs:subClassOf>" in x and n < line_of(owl, 'rdf:resource="#CanSoftGrip"'))
    assert f"[SoftGripper ⊑ ∃hasSkill.CanSoftGrip; {owl}:{restriction}]" in result.stdout
    assert f"[CanSoftGrip ⊑ CanGrip; {owx}:{line_of(owx, '<SubClassOf>')}]" in result.stdout
    inferred = next(x for x in result.stdout.splitlines() if "every 'soft gripper' has the skill 'can grip'" in x)
    assert "SoftGripper ⊑ ∃hasSkill.CanSoftGrip, CanSoftGrip ⊑ CanGrip" in inferred and "inferred" in inferred


def copy_lab(tmp_path: Path) -> Path:
    return Path(shutil.copytree(LAB, tmp_path / "lab"))


def test_an_import_the_catalog_does_not_map_is_one_line_naming_the_iri(tmp_path: Path) -> None:
    lab = copy_lab(tmp_path)
    (lab / "ontology" / "catalog-v001.xml").unlink()
    shutil.move(lab / "ontology" / "imports" / "skills.owx", tmp_path / "skills.owx")  # nowhere in the library
    result = runner.invoke(app, ["--library", str(lab), "vocab"])
    assert result.exit_code == 2
    owl = lab / "ontology" / "lab.owl"
    assert result.stderr.strip().splitlines() == [
        f"{owl}:{line_of(owl, SKILLS_IRI)}: owl:imports <{SKILLS_IRI}> is not resolved: no catalog-v001.xml maps it "
        f"and no file of the library {lab} declares that ontology (imports are never fetched from the network)"]
    checked = runner.invoke(app, ["validate", str(lab)])  # validate: the same line among its findings, exit 2
    assert checked.exit_code == 2
    assert result.stderr.strip() in checked.stdout.splitlines()


def test_an_import_resolves_to_the_library_file_that_declares_its_iri(tmp_path: Path) -> None:
    lab = copy_lab(tmp_path)
    (lab / "ontology" / "catalog-v001.xml").unlink()
    (lab / "ontology" / "imports" / "skills.owx").rename(lab / "skills-by-another-name.owx")
    result = runner.invoke(app, ["--library", str(lab), "vocab", "--json"])
    assert result.exit_code == 0, result.output
    assert "http://example.org/protege-lab#CanSoftGrip" in {s["iri"] for s in json.loads(result.stdout)["skills"]}


def test_a_catalog_entry_outside_the_library_is_refused(tmp_path: Path) -> None:
    lab = copy_lab(tmp_path)
    shutil.move(lab / "ontology" / "imports" / "skills.owx", tmp_path / "skills.owx")
    catalog = lab / "ontology" / "catalog-v001.xml"
    catalog.write_text(catalog.read_text().replace('uri="imports/skills.owx"', 'uri="../../skills.owx"'))
    result = runner.invoke(app, ["--library", str(lab), "vocab"])
    assert result.exit_code == 2
    assert "is outside the library folder" in result.stderr and SKILLS_IRI in result.stderr


def pnp(*args: str) -> dict[str, Any]:
    """``pnp ARGS`` in a process of its own (the reasoner's closure comes from the on-disk cache if keyed so)."""
    done = subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return cast(dict[str, Any], json.loads(done.stdout))


def test_editing_an_imported_file_reclassifies(tmp_path: Path) -> None:
    lab = copy_lab(tmp_path)
    cell = ["capabilities", "--json", "--cell", str(lab / "cells" / "bin-picking-soft.yaml")]
    before = pnp("--library", str(lab), *cell)
    owx = lab / "ontology" / "imports" / "skills.owx"
    owx.write_text(owx.read_text().replace('<Class IRI="http://plugnproduce.org/ontology#CanGrip"/>',
                                           '<Class IRI="http://plugnproduce.org/ontology#CanScrew"/>'))
    after = pnp("--library", str(lab), *cell)
    assert "pick" in {o["command"] for o in before["offered"]}
    assert "pick" not in {o["command"] for o in after["offered"]}


@pytest.mark.parametrize("suffix", [".owl", ".owx"])
def test_a_hostile_xml_ontology_is_refused_before_any_rdf_parser(tmp_path: Path, suffix: str) -> None:
    lab = tmp_path / "lab"
    (lab / "ontology").mkdir(parents=True)
    bomb = lab / "ontology" / f"bomb{suffix}"
    bomb.write_text('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
                    + "".join(f'<!ENTITY a{i} "{"&a;" * 10}">' for i in range(20))
                    + ']>\n<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">&a19;</rdf:RDF>\n')
    result = runner.invoke(app, ["--library", str(lab), "vocab"])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"{bomb}:2: DOCTYPE/ENTITY declarations are refused")


def test_an_xml_document_that_is_no_ontology_is_named(tmp_path: Path) -> None:
    lab = tmp_path / "lab"
    (lab / "ontology").mkdir(parents=True)
    (lab / "ontology" / "notes.owl").write_text("<?xml version='1.0'?>\n<notes><n>hi</n></notes>\n")
    result = runner.invoke(app, ["--library", str(lab), "vocab"])
    assert result.exit_code == 2
    assert "notes.owl:2: an XML document with root <notes>; expected RDF/XML" in result.stderr


def test_every_axiom_of_the_xml_forms_is_found_at_an_element_naming_its_class(tmp_path: Path) -> None:
    owl = save_as_rdfxml(ontology_path() / "pnp.ttl", tmp_path / "pnp.owl")
    owx = tmp_path / "pnp.owx"
    owx.write_text(pyhornedowl.open_ontology_from_file(str(owl)).save_to_string("owx"))
    taxonomy = load_taxonomy()
    def said(a: Axiom) -> tuple[str, frozenset[str]]:  # an equivalence may be written either way round
        return a.kind, frozenset((a.sub, a.sup)) if a.kind == "equivalent" else frozenset((a.sub, "⊑" + a.sup))

    turtle = {said(a) for a in load_ontology([ontology_path() / "pnp.ttl"], taxonomy).axioms}
    for path in (owl, owx):
        onto = load_ontology([path], taxonomy)
        assert {said(a) for a in onto.axioms} == turtle
        lines = path.read_text().splitlines()
        for a in onto.axioms:
            assert a.where.line is not None, a.formula()
            element = "\n".join(lines[a.where.line - 1:a.where.line + 8])  # the element's opening and body
            assert a.sup.rsplit("#", 1)[1] in element, (a.formula(), path.name, a.where.line)


def test_validate_reads_a_library_s_rdfxml_and_owlxml_files(tmp_path: Path) -> None:
    report = service.validate([LAB])
    assert report.valid, report.problems
    assert {"lab.owl", "skills.owx", "soft-gripper.ttl"} <= {Path(f).name for f in report.files}
    lab = copy_lab(tmp_path)
    owl = lab / "ontology" / "lab.owl"
    owl.write_text(owl.read_text().replace("</owl:Class>", "</owl:Klass>", 1))
    result = runner.invoke(app, ["validate", str(owl)])
    assert result.exit_code == 2
    assert result.stdout.startswith(f"{owl}:") and "malformed XML: Opening and ending tag mismatch" in result.stdout


@settings(max_examples=80, deadline=None, derandomize=True)
@given(name=st.sampled_from(["lab.owl", "imports/skills.owx"]), rng=st.randoms(use_true_random=False))
def test_a_mutated_protege_file_is_read_or_refused_in_one_line(name: str, rng: random.Random) -> None:
    data = bytearray((LAB / "ontology" / name).read_bytes())
    for _ in range(rng.randint(1, 6)):  # flip, cut, or repeat a piece
        at = rng.randrange(len(data))
        choice = rng.random()
        if choice < 0.4:
            data[at] = rng.randrange(256)
        elif choice < 0.7:
            del data[at:at + rng.randint(1, 40)]
        else:
            data[at:at] = data[at:at + rng.randint(1, 200)] * rng.randint(1, 20)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / Path(name).name
        path.write_bytes(bytes(data))
        try:
            read_tbox_file(path)
        except DescriptionError as exc:
            message = exc.location_message()
            assert "\n" not in message and "Traceback" not in message and message.startswith(str(path))
