"""The reasoner on a hierarchical Device State Chart (the PackML-style screwdriver of the packml-screwing library):
a state inside compound states has their concepts, a superstate's transitions leave every state inside it, and a
skill reported aborted must be cleared before it can screw."""

from __future__ import annotations

from pathlib import Path

from plugnproduce import service
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.facts import device_facts

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "packml-screwing"
CELL = LIBRARY / "cells" / "packml-screwing.yaml"
TASK = LIBRARY / "tasks" / "screw-twice.yaml"
PNP = "http://plugnproduce.org/ontology#"


def test_facts_give_a_nested_state_its_own_and_its_superstates_concepts_and_edges() -> None:
    k = service.knowledge((LIBRARY,))
    screwdriver = service.cell(CELL).device("packml-screwdriver")
    facts = set(device_facts(screwdriver, k.taxonomy, ()))
    d = "packml-screwdriver"
    assert s.StateIs(d, "Execute", PNP + "Screwing") in facts  # from Running, around it
    assert s.StateIs(d, "Execute", "http://example.org/packml#Execute") in facts
    assert s.StateIs(d, "Held", PNP + "Screwing") not in facts  # Held is not inside Running
    assert s.Edge(d, "Execute", "Stopping") in facts  # Operating's Stop, taken from inside Running
    assert s.Edge(d, "Complete", "Idle") in facts and s.Edge(d, "Idle", "Starting") in facts
    assert s.Initial(d, "Idle") in facts
    assert not any(isinstance(f, s.ChartState) and f.x in ("Abortable", "Operating", "Running") for f in facts)


def test_the_screw_command_is_offered_with_the_hierarchical_screwdriver() -> None:
    offered = service.capabilities(CELL)
    screw = next(c for c in offered.offered if c.command == "screw")
    assert screw.bindings == ({"robot": "cobot", "screwdriver": "packml-screwdriver"},)


def test_a_skill_reported_aborted_is_in_the_wrong_state_to_screw() -> None:
    cell = service.cell(CELL).reported({"packml-screwdriver": "Aborted"})
    checked = service.check(TASK, cell)
    assert not checked.plausible
    (problem,) = checked.problems
    assert (problem.step, problem.kind, problem.device, problem.state) == (1, "wrong_state", "packml-screwdriver",
                                                                           "Aborted")
    assert problem.needed == PNP + "ToolIdle"
