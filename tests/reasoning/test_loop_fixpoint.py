"""A loop whose every step is plausible, but whose iteration does not bring its device back (``loop_fixpoint``).

The library is written here, outside the package: a three-station turntable whose device state chart is a cycle
(station A, B, C, A again), and one process command, ``index-table``, that moves it one station on from any
station. Each step of a loop of ``index-table`` finds the table at a station, as the role needs; but a loop of one
``index-table`` leaves it a station further each iteration, so the generated chart's one copy of the later
iterations could not serve them all. Check and batch must both refuse it, and both let through a loop of three
``index-table``, which brings the table back round to where it began, and a loop of one ``index-table`` that runs
at most twice (no iteration starts from where the second left the table).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce.cli import app

TT = "http://example.org/turntable#"
ONTOLOGY = f"""@prefix pnp:  <http://plugnproduce.org/ontology#> .
@prefix tt:   <{TT}> .
@prefix owl:  <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .

<http://example.org/turntable> a owl:Ontology .

tt:CanIndex a owl:Class ; rdfs:subClassOf pnp:Skill ; rdfs:label "can index" ; pnp:mandatoryState tt:AtStation .
tt:TableState a owl:Class ; rdfs:subClassOf pnp:StateConcept ; rdfs:label "table state" .
tt:AtStation a owl:Class ; rdfs:subClassOf tt:TableState ; rdfs:label "at a station" .
tt:AtStationA a owl:Class ; rdfs:subClassOf tt:AtStation ; rdfs:label "at station A" .
tt:AtStationB a owl:Class ; rdfs:subClassOf tt:AtStation ; rdfs:label "at station B" .
tt:AtStationC a owl:Class ; rdfs:subClassOf tt:AtStation ; rdfs:label "at station C" .
tt:Indexing a owl:Class ; rdfs:subClassOf tt:TableState ; rdfs:label "indexing" .
tt:Turntable a owl:Class ; rdfs:subClassOf pnp:Device ; rdfs:label "turntable" ;
    rdfs:subClassOf [ a owl:Restriction ; owl:onProperty pnp:hasSkill ; owl:someValuesFrom tt:CanIndex ] .
"""
DEVICE = """@prefix pnp:  <http://plugnproduce.org/ontology#> .
@prefix tt:   <http://example.org/turntable#> .
@prefix dev:  <http://example.org/turntable/devices/> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .

dev:turntable a tt:Turntable ;
    rdfs:label "Three-station turntable" ;
    pnp:protocol pnp:UPnP ;
    pnp:endpoint "upnp://127.0.0.1:0" ;
    pnp:stateChart <turntable.scxml> .
"""
SCXML = ('<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:pnp="http://plugnproduce.org/ontology#"\n'
         '       version="1.0" name="{name}" initial="{initial}">\n{body}</scxml>\n')


def _station(here: str, on: str) -> str:
    """Station ``here`` of the turntable's cycle, and the indexing that takes it to station ``on``."""
    return f"""  <state id="at_{here.lower()}" pnp:concept="{TT}AtStation{here}">
    <transition event="upnp.request.Index" target="to_{on.lower()}"/>
  </state>
  <state id="to_{on.lower()}" pnp:concept="{TT}Indexing">
    <onentry><send event="index.done" delay="50ms"/></onentry>
    <transition event="index.done" target="at_{on.lower()}">
      <send event="upnp.event.indexed" type="upnp"/>
    </transition>
  </state>
"""


PROCESS = """@prefix pnp:  <http://plugnproduce.org/ontology#> .
@prefix tt:   <http://example.org/turntable#> .
@prefix ttp:  <http://example.org/turntable/processes/> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .

ttp:index-table a pnp:Process ;
    rdfs:label "index the turntable one station on" ;
    pnp:generalChart <index-table.scxml> ;
    pnp:hasRole ttp:index-table-table .

ttp:index-table-table a pnp:Role ; pnp:roleName "table" ; pnp:requiresSkill tt:CanIndex .
"""
REGION = f"""  <parallel id="index-table">
    <state id="table" pnp:role="table" initial="table_at_station">
      <state id="table_at_station" pnp:concept="{TT}AtStation">
        <transition target="table_indexing"/>
      </state>
      <state id="table_indexing" pnp:concept="{TT}Indexing">
        <transition target="table_indexed"/>
      </state>
      <final id="table_indexed" pnp:concept="{TT}AtStation"/>
    </state>
  </parallel>
"""
TASK = """task: {name}
steps:
  - command: index-table
  - loop:
      max: {most}
      steps:
{body}"""
FILES = {
    "ontology/turntable.ttl": ONTOLOGY,
    "devices/turntable.ttl": DEVICE,
    "devices/turntable.scxml": SCXML.format(name="turntable", initial="at_a", body="".join(
        _station(here, on) for here, on in (("A", "B"), ("B", "C"), ("C", "A")))),
    "processes/index-table.ttl": PROCESS,
    "processes/index-table.scxml": SCXML.format(name="index-table", initial="index-table", body=REGION),
    "cells/turntable-cell.yaml": "cell: turntable-cell\nlibraries:\n  - ..\ndevices:\n  - turntable\n",
    # one station on per iteration: A to B before the loop, B to C in the first iteration, C to A in the second
    "tasks/index-once.yaml": TASK.format(name="index-once", most=10, body="        - command: index-table\n"),
    # a whole round per iteration: every iteration starts and ends at station B
    "tasks/index-round.yaml": TASK.format(name="index-round", most=10, body="        - command: index-table\n" * 3),
    # at most two iterations: the generated chart's copy of the later ones runs once, from where the first left
    "tasks/index-twice.yaml": TASK.format(name="index-twice", most=2, body="        - command: index-table\n"),
    "configs.jsonl": '{"config": "table", "devices": ["turntable"]}\n',
}
FIRST_STEP_OF_THE_LOOP = 7
"""The line of the loop's first step (``- command: index-table`` under ``steps:``) in both tasks."""


@pytest.fixture(scope="module")
def library(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("turntable")
    for name, text in FILES.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text, encoding="utf-8")
    code, out = pnp(root, "validate", str(root))
    assert code == 0, out
    lines = (root / "tasks" / "index-once.yaml").read_text(encoding="utf-8").splitlines()
    assert lines[FIRST_STEP_OF_THE_LOOP - 2:FIRST_STEP_OF_THE_LOOP] == ["      steps:", "        - command: index-table"]
    return root


def pnp(library: Path, *args: str) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["--library", str(library), *args])
    assert isinstance(result.exception, SystemExit | None), result.exception
    return result.exit_code, result.stdout


def check(library: Path, task: str, *more: str) -> tuple[int, str]:
    return pnp(library, "check", str(library / "tasks" / task), "--cell", str(library / "cells" / "turntable-cell.yaml"),
               *more)


def batch(library: Path, task: str) -> dict[str, object]:
    code, out = pnp(library, "batch", str(library / "configs.jsonl"), "--task", str(library / "tasks" / task),
                    "--workers", "1")
    assert code == 0, out
    (row,) = [json.loads(line) for line in out.splitlines()]
    return dict(row)


def test_check_says_a_loop_that_leaves_the_table_a_station_further_is_not_plausible_at_its_first_step(
        library: Path) -> None:
    code, out = check(library, "index-once.yaml")
    assert code == 1, out
    assert out.splitlines() == [
        "task index-once in cell turntable-cell: implausible (1 problem(s))",
        f"{library / 'tasks' / 'index-once.yaml'}:{FIRST_STEP_OF_THE_LOOP}: loop iteration: device turntable ends an "
        "iteration in state 'at_a', but the iteration before left it in 'at_c'; each iteration must leave every "
        "device as it found it"]


def test_the_finding_is_loop_fixpoint_of_the_turntable_at_the_loops_first_step(library: Path) -> None:
    code, out = check(library, "index-once.yaml", "--json")
    assert code == 1, out
    doc = json.loads(out)
    assert doc["plausible"] is False
    assert [(p["kind"], p["step"], p["command"], p["device"], p["state"], p["where"]) for p in doc["problems"]] == [
        ("loop_fixpoint", 3, "index-table", "turntable", "at_a",
         f"{library / 'tasks' / 'index-once.yaml'}:{FIRST_STEP_OF_THE_LOOP}")]
    # every step on its own is plausible: the table is at a station before each
    assert [s["states"] for s in doc["steps"]] == [{"turntable": "at_a"}, {"turntable": "at_b"},
                                                   {"turntable": "at_c"}]


def test_the_batch_gives_the_same_verdict_and_reason(library: Path) -> None:
    row = batch(library, "index-once.yaml")
    assert row["offered"] == ["index-table"] and row["plausible"] == []
    assert row["purchase"] == {"options": [], "impossible": (
        "step 3 of index-once: device turntable ends a loop iteration in another state than the iteration began in; "
        "adding devices cannot cure it")}


def test_a_loop_that_brings_the_table_back_round_is_plausible_in_check_and_batch(library: Path) -> None:
    code, out = check(library, "index-round.yaml")
    assert code == 0, out
    assert out.splitlines()[0] == "task index-round in cell turntable-cell: plausible"
    row = batch(library, "index-round.yaml")
    assert row["plausible"] == ["index-round"] and row["purchase"] is None


def test_a_loop_of_at_most_two_iterations_need_not_bring_the_table_back(library: Path) -> None:
    """No iteration starts from where the second left the table: each starts where the step before it leaves it."""
    code, out = check(library, "index-twice.yaml")
    assert code == 0, out
    assert out.splitlines()[0] == "task index-twice in cell turntable-cell: plausible"
    row = batch(library, "index-twice.yaml")
    assert row["plausible"] == ["index-twice"] and row["purchase"] is None
