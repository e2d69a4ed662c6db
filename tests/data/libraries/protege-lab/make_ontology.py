"""How protege-lab's ontology was written, as an engineer's tools save it: ``ontology/lab.owl`` in RDF/XML by
owlready2, importing ``http://example.org/protege-lab/skills``, which ``ontology/catalog-v001.xml`` maps to
``ontology/imports/skills.owx`` (OWL/XML, written by py-horned-owl). Run: ``python make_ontology.py ontology``."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import owlready2
import pyhornedowl
import rdflib

PRE = """@prefix pnp: <http://plugnproduce.org/ontology#> . @prefix lab: <http://example.org/protege-lab#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
"""
LAB = PRE + """
<http://example.org/protege-lab> a owl:Ontology ; rdfs:label "Protégé lab extension" .
lab:SoftGripper a owl:Class ; rdfs:subClassOf pnp:Gripper ; rdfs:label "soft gripper" ;
    rdfs:subClassOf [ a owl:Restriction ; owl:onProperty pnp:hasSkill ; owl:someValuesFrom lab:CanSoftGrip ] ,
                    [ a owl:Restriction ; owl:onProperty pnp:hasSkill ; owl:someValuesFrom pnp:CanRelease ] .
"""
SKILLS = PRE + """
<http://example.org/protege-lab/skills> a owl:Ontology ; rdfs:label "Protégé lab skills" .
lab:CanSoftGrip a owl:Class ; rdfs:subClassOf pnp:CanGrip ; rdfs:label "can grip softly" .
lab:Cupping a owl:Class ; rdfs:subClassOf pnp:Closing ; rdfs:label "cupping" .
pnp:hasSkill a owl:ObjectProperty .
"""

def rdfxml(ttl: str, iri: str, imports: tuple[str, ...] = ()) -> bytes:
    nt = rdflib.Graph().parse(data=ttl, format="turtle").serialize(format="nt", encoding="utf-8")
    world = owlready2.World()
    onto = world.get_ontology(iri).load(fileobj=io.BytesIO(nt), format="ntriples")
    for other in imports:  # named, not loaded: owlready2 would fetch them
        onto.imported_ontologies.append(world.get_ontology(other))
    out = io.BytesIO()
    onto.save(file=out, format="rdfxml")
    return out.getvalue()


if __name__ == "__main__":
    folder = Path(sys.argv[1])
    imports = ("http://plugnproduce.org/ontology", "http://example.org/protege-lab/skills")
    (folder / "lab.owl").write_bytes(rdfxml(LAB, "http://example.org/protege-lab", imports))
    skills = rdfxml(SKILLS, "http://example.org/protege-lab/skills").decode()
    (folder / "imports" / "skills.owx").write_text(pyhornedowl.open_ontology_from_string(skills, "owl")
                                                   .save_to_string("owx"))
