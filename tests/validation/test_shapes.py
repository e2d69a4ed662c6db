"""Every SHACL shape, with a conforming and a violating description.

Each case copies a built-in description, applies one edit and expects exactly the
shape's message at the right line; the unedited copy is the conforming example.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from plugnproduce.resources import descriptions_path
from plugnproduce.validation import validate_paths
from tests.conftest import edit

DESCRIPTIONS = descriptions_path()

# (shape, kind, name, old text, new text, line of the problem in the Turtle file, part of the message)
CASES = [
    ("DeviceShape/skill", "devices", "cnc", "a pnp:CNCMachine", "a pnp:Machine", 6,
     "no skill, declared or implied by its class"),
    ("DeviceShape/protocol", "devices", "gripper", "pnp:protocol pnp:XIRP", "pnp:protocol pnp:Modbus", 6,
     "exactly one pnp:protocol, pnp:XIRP, pnp:UPnP or pnp:OPCUA"),
    ("DeviceShape/endpoint", "devices", "robot", '"xirp://127.0.0.1:0"', '"127.0.0.1"', 6, "pnp:endpoint"),
    ("DeviceShape/chart", "devices", "gripper", "pnp:stateChart <gripper.scxml> ;", "", 6, "pnp:stateChart"),
    ("DeviceShape/cost", "devices", "gripper", "pnp:cost 1800", "pnp:cost -5", 6, "pnp:cost"),
    ("DeviceShape/mandatory", "devices", "vacuum-gripper", 'pnp:concept="ClosedWithPart"', 'pnp:concept="Running"',
     6, "lacks the mandatory state 'Closed'"),
    ("ChartStateShape", "devices", "gripper", 'pnp:concept="Configuring"', 'pnp:concept="GripForce"', 0,
     "not a state concept of the ontology"),
    ("ProcessShape/label", "processes", "pick", 'rdfs:label "pick" ;', "", 6, "rdfs:label"),
    ("ProcessShape/role", "processes", "open-gripper", "pnp:hasRole proc:open-gripper-gripper",
     "pnp:hasRole proc:nothing", 6, "pnp:hasRole"),
    ("RoleShape/skill", "processes", "pick", 'pnp:requiresSkill pnp:CanGrip', 'pnp:requiresSkill pnp:Open', 14,
     "pnp:requiresSkill, a skill"),
    ("RoleShape/start", "processes", "pick", 'id="gripper_open" pnp:concept="Open"', 'id="gripper_open" pnp:concept="Speed"',
     14, "start state"),
    ("ParameterShape/datatype", "processes", "pick", "pnp:datatype xsd:decimal ;\n    pnp:unit \"N\"",
     "pnp:datatype xsd:float ;\n    pnp:unit \"N\"", 41, "pnp:datatype"),
    ("ParameterShape/range", "processes", "pick", "pnp:minValue 10 ; pnp:maxValue 140", "pnp:minValue 150 ; pnp:maxValue 140",
     41, "must not exceed"),
    ("ParameterShape/default", "processes", "pick", "pnp:defaultValue 40", "pnp:defaultValue 400", 41,
     "default 400 of parameter 'grip_force' lies outside its range [10, 140]"),
    ("ParameterShape/quantity", "processes", "pick", "pnp:quantity pnp:GripForce", "pnp:quantity pnp:Open", 41,
     "pnp:quantity"),
    ("RequestArgumentShape/range", "devices", "gripper", "pnp:minValue 20 ; pnp:maxValue 100",
     "pnp:minValue 200 ; pnp:maxValue 100", 20, "argument's pnp:minValue must not exceed"),
    ("RequestArgumentShape/required", "devices", "gripper", 'pnp:request "Close" ;',
     'pnp:request "Close" ; pnp:required "yes" ;', 20, "pnp:required is one boolean"),
    ("RequestArgumentShape/reach", "devices", "robot", "pnp:maxReach 1.45", "pnp:maxReach 0", 19,
     "pnp:maxReach is one positive"),
    ("RequestArgumentShape/datatype", "devices", "cobot", "pnp:datatype xsd:decimal", "pnp:datatype xsd:float", 26,
     "argument's pnp:datatype"),
]


def _copy(tmp_path: Path, kind: str, name: str) -> tuple[Path, Path]:
    ttl = Path(shutil.copy(DESCRIPTIONS / kind / f"{name}.ttl", tmp_path))
    scxml = Path(shutil.copy(DESCRIPTIONS / kind / f"{name}.scxml", tmp_path))
    return ttl, scxml


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_conforming_example(tmp_path: Path, case: tuple) -> None:
    _, kind, name, *_ = case
    _copy(tmp_path, kind, name)
    assert validate_paths([tmp_path]).problems == []


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_violating_example(tmp_path: Path, case: tuple) -> None:
    _, kind, name, old, new, line, needle = case
    ttl, scxml = _copy(tmp_path, kind, name)
    edit(scxml if old in scxml.read_text() else ttl, old, new)
    problems = validate_paths([tmp_path]).sorted()
    assert any(needle in p.message for p in problems), [str(p) for p in problems]
    hit = next(p for p in problems if needle in p.message)
    if line:
        assert (hit.file, hit.line) == (str(ttl), line)
    else:
        assert hit.file == str(scxml) and hit.line > 0


def test_task_value_shapes_conform_for_builtin_tasks() -> None:
    assert validate_paths([DESCRIPTIONS / "tasks"]).problems == []


def _task_text(rounds: int) -> str:
    step = ("  - command: place\n    params:\n      place_pose: [0.6, -0.2, 0.1, 0, 180, 0]\n      speed: 9999\n"
            "  - command: pick\n    params:\n      grip_force: strong\n")
    return "task: t\nsteps:\n" + step * rounds


def test_a_task_s_values_cost_the_same_queries_whatever_its_length(monkeypatch: pytest.MonkeyPatch) -> None:
    # pySHACL parses a constraint's query anew for each focus node: one per value took ~20 s for a
    # 100-step task in the editor (issue 15); the task's values are now checked by one query per task
    import rdflib

    from plugnproduce import service

    queries: list[str] = []
    real = rdflib.Graph.query

    def counted(self: rdflib.Graph, query: object, *args: object, **kwargs: object) -> object:
        queries.append(str(query))
        return real(self, query, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(rdflib.Graph, "query", counted)
    counts, findings = [], []
    for rounds in (1, 50):
        queries.clear()
        task = service.task_from_text(_task_text(rounds), "t.yaml")
        findings.append(service.validate_tasks([task]).sorted())
        counts.append(len(queries))
    assert counts[0] == counts[1]
    assert len(findings[1]) == 2 * 50  # each bad value still found, at its own line
    assert [p.line for p in findings[1][:2]] == [6, 9]
    assert findings[1][0].message == "step 1: parameter 'speed' is 9999 %; expected a value from 1 to 100 %"
    assert findings[1][1].message == "step 2: parameter 'grip_force' takes a number; found strong"


def test_issue_15_a_shape_pyshacl_cannot_run_is_one_line_not_an_attribute_error() -> None:
    # pySHACL returns (not raises) a ValidationFailure when it refuses a SPARQL constraint, here
    # for a nested select it reads in the query's comment; shape_problems took it for a report
    import rdflib

    from plugnproduce.description.datagraph import DataGraph
    from plugnproduce.errors import OntologyError
    from plugnproduce.validation.shapes import shape_problems

    shapes = rdflib.Graph().parse(format="turtle", data='''
        @prefix sh: <http://www.w3.org/ns/shacl#> .
        @prefix ex: <urn:ex:> .
        ex:S a sh:NodeShape ; sh:targetNode ex:a ;
            sh:sparql [ sh:select """SELECT $this WHERE { # not { SELECT ?o } here
                $this ?p ?o . }""" ] .''')
    kg = DataGraph()
    kg.graph.add((rdflib.URIRef("urn:ex:a"), rdflib.URIRef("urn:ex:p"), rdflib.Literal(1)))
    with pytest.raises(OntologyError) as info:
        shape_problems(kg, shapes)
    assert str(info.value).startswith("the SHACL shapes could not be run: All potentially pre-bound variables")
    assert "\n" not in str(info.value)
