"""Explain-why: derivations through rules, ontology axioms and charts; counterfactuals the reasoner confirms."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.model import Cell, DeviceDescription, Where
from plugnproduce.reasoning import Node
from tests.reasoning.conftest import TASKS

ADAPTIVE = Path(__file__).parent.parent / "data" / "libraries" / "adaptive-gripper"
INVALID = TASKS / "bin-picking-invalid.yaml"


def line_at(where: Where | None) -> str:
    assert where is not None and where.line is not None
    return Path(where.file).read_text(encoding="utf-8").splitlines()[where.line - 1]


def nodes(tree: Node, kind: str) -> list[Node]:
    return [n for n in tree.walk() if n.kind == kind]


def test_an_offered_process_is_derived_from_the_grippers_class_axiom(cell: Cell) -> None:
    tree = service.explain_offered(cell, "pick").derivation
    axiom = next(n for n in nodes(tree, "owl") if n.detail == "ParallelGripper ⊑ ∃hasSkill.CanParallelGrip")
    assert "pnp:ParallelGripper" in line_at(axiom.where) or "CanParallelGrip" in line_at(axiom.where)
    assert axiom.where is not None and axiom.where.file.endswith("pnp.ttl")
    inferred = next(n for n in nodes(tree, "owl") if n.text == "every 'parallel gripper' has the skill 'can grip'")
    assert inferred.inferred and axiom in inferred.children


def test_the_derivation_cites_the_rules_at_their_lines(cell: Cell) -> None:
    tree = service.explain_offered(cell, "pick").derivation
    rules = {Path(n.where.file).name: n for n in nodes(tree, "asp") if n.where}
    assert {"offered.lp", "roles.lp"} <= set(rules)
    for n in nodes(tree, "asp"):
        head = n.detail.split("(")[0]
        assert line_at(n.where).startswith(head + "(")


def test_the_derivation_names_the_chart_states_the_gripper_goes_through(cell: Cell) -> None:
    tree = service.explain_offered(cell, "pick").derivation
    states = {line_at(n.where).strip() for n in nodes(tree, "chart") if n.where and n.where.file.endswith("gripper.scxml")}
    assert any('id="open"' in s for s in states) and any('id="closed"' in s for s in states)


def test_the_plain_sentences_name_no_iri_and_no_file(cell: Cell) -> None:
    for command in ("pick", "screw"):
        text = " ".join(s for _, s in service.explain_offered(cell, command).derivation.sentences())
        assert "http" not in text and "pnp:" not in text and ".ttl" not in text and ".lp" not in text


def test_depth_cuts_the_derivation(cell: Cell) -> None:
    tree = service.explain_offered(cell, "pick").derivation
    assert [level for level, _ in tree.sentences(depth=1)] == [0, 1, 1]
    assert len(tree.sentences()) > len(tree.sentences(depth=2))


def test_every_process_the_cell_does_not_offer_has_a_confirmed_counterfactual(cell: Cell) -> None:
    catalogue = service.catalogue()
    for no in service.capabilities(cell).not_offered:
        ex = service.explain_offered(cell, no.command)
        assert ex.answer is False and ex.counterfactuals, no.command
        first = ex.counterfactuals[0]
        added = [d for d in catalogue if d.id in first.devices]
        changed = Cell(cell.name, tuple(d for d in cell.devices if d.id != first.replaces) + tuple(added))
        assert service.capabilities(changed).offers(no.command)


def test_when_no_counterfactual_exists_it_says_so(cell: Cell) -> None:
    ex = service.explain_offered(cell, "transport", catalogue_or_folder=[])
    assert ex.counterfactuals == () and ex.none_exists and "transport" in ex.none_exists


def test_a_questioned_yes_names_the_devices_it_rests_on(cell: Cell) -> None:
    ex = service.explain_offered(cell, "pick")
    assert {c.devices for c in ex.counterfactuals} == {("robot",), ("gripper",)}
    for c in ex.counterfactuals:
        assert not service.capabilities(cell.without(c.devices[0])).offers("pick")


def test_a_step_that_is_not_plausible_says_where_the_state_came_from(cell: Cell) -> None:
    ex = service.explain_plausible(INVALID, cell, 2)
    sentences = [s for _, s in ex.derivation.sentences()]
    assert ex.answer is False
    assert "step 1 (bin-pick) left device 'gripper' in state 'closed'" in sentences
    assert "'closed' is not a kind of 'open'" in sentences
    assert [(c.kind, c.devices, c.state) for c in ex.counterfactuals][0] == ("state", ("gripper",), "open")
    edits = [c for c in ex.counterfactuals if c.kind == "edit_task"]
    assert edits and all(c.confirmed for c in edits)
    assert edits[-1].text == "insert open-gripper before step 2 (bin-pick)" and "holds the part" in edits[-1].side_effects[0]


def test_a_library_device_is_explained_through_the_librarys_axiom() -> None:
    knowledge = service.knowledge_for_cell(ADAPTIVE / "cells" / "bin-picking-adaptive.yaml")
    ex = service.explain_offered(ADAPTIVE / "cells" / "bin-picking-adaptive.yaml", "pick", knowledge)
    axiom = next(n for n in nodes(ex.derivation, "owl") if n.detail == "AdaptiveParallelGripper ⊑ ParallelGripper")
    assert axiom.where is not None and axiom.where.file.endswith("adaptive-gripper.ttl")
    assert "ag:AdaptiveParallelGripper" in line_at(axiom.where)


def test_labels_follow_the_language_asked_for() -> None:
    cell = ADAPTIVE / "cells" / "bin-picking-adaptive.yaml"
    knowledge = service.knowledge_for_cell(cell)
    german = " ".join(s for _, s in service.explain_offered(cell, "pick", knowledge, language="de")
                      .derivation.sentences())
    english = " ".join(s for _, s in service.explain_offered(cell, "pick", knowledge).derivation.sentences())
    assert "adaptiver Parallelgreifer" in german and "adaptive parallel gripper" in english


def test_an_unknown_process_is_a_key_error(cell: Cell) -> None:
    with pytest.raises(KeyError):
        service.explain_offered(cell, "teleport")


def test_a_reason_in_plain_words_drops_the_terms(cell: Cell) -> None:
    (problem,) = service.check(INVALID, cell).problems
    assert "(pnp:Closed)" in problem.reason.text and "pnp:" not in problem.reason.plain
    assert "is in state 'closed' [closed], left there by step 1 (bin-pick)" in problem.reason.plain


def test_a_process_no_device_has_the_skill_for_is_derived_from_the_missing_skill(cell: Cell) -> None:
    tree = service.explain_offered(cell, "screw").derivation
    (rule,) = [n for n in nodes(tree, "asp") if n.detail.startswith("no_skill(")]
    assert '"screwdriver"' in rule.detail and "CanScrew" in rule.detail
    assert line_at(rule.where).startswith("no_skill(")


def test_a_gripper_lacking_a_state_is_derived_from_the_missing_state(cell: Cell, device) -> None:
    gripper = device("gripper")
    broken = DeviceDescription(**{**gripper.__dict__, "states": tuple(s for s in gripper.states if s.id != "closed")})
    tree = service.explain_offered(cell.without("gripper").with_device(broken), "pick").derivation
    (rule,) = [n for n in nodes(tree, "asp") if n.detail.startswith("lacks_state(")]
    assert '"gripper",2,' in rule.detail and "Closed" in rule.detail
    assert line_at(rule.where).startswith("lacks_state(")


def test_a_gripper_that_cannot_close_is_derived_from_the_unreachable_state(cell: Cell, device) -> None:
    gripper = device("gripper")
    one_way = DeviceDescription(**{**gripper.__dict__, "transitions": tuple(
        t for t in gripper.transitions if t.target not in ("closing", "closed"))})
    tree = service.explain_offered(cell.without("gripper").with_device(one_way), "pick").derivation
    (rule,) = [n for n in nodes(tree, "asp") if n.detail.startswith("unreachable(")]
    assert '"gripper",1,"open",' in rule.detail and "Closed" in rule.detail
    assert line_at(rule.where).startswith("unreachable(")
