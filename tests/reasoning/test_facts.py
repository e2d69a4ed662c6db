"""The typed boundary and the facts built from descriptions."""

from __future__ import annotations

import clingo
import pytest

from plugnproduce import service
from plugnproduce.description.model import Cell
from plugnproduce.errors import EncodingError
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.facts import device_facts, milli, process_facts, task_facts, value_kinds
from plugnproduce.reasoning.asp.terms import decode, program, quote
from tests.reasoning.conftest import task

PNP = "http://plugnproduce.org/ontology#"


def test_an_atom_round_trips_through_asp_text() -> None:
    atom = s.WrongState("c", "t", 2, "gripper", 'odd "id"\\', "closed", PNP + "Open")
    (symbol,) = [clingo.parse_term(atom.text())]
    assert decode([symbol])[s.WrongState] == [atom]


def test_quote_escapes() -> None:
    assert quote('a"b\\c\nd') == '"a\\"b\\\\c\\nd"'


def test_a_shown_atom_no_predicate_declares_is_an_error() -> None:
    with pytest.raises(EncodingError, match="no typed predicate"):
        decode([clingo.parse_term("mystery(1)")])


def test_a_wrong_argument_type_is_an_error() -> None:
    with pytest.raises(EncodingError):
        s.Cost("gripper", 1.5).text()  # type: ignore[arg-type]


def test_state_concepts_are_closed_under_the_taxonomy(device) -> None:
    facts = set(device_facts(device("vacuum-gripper"), service.knowledge().taxonomy, ()))
    assert s.StateIs("vacuum-gripper", "released", PNP + "Open") in facts  # Released is equivalent to Open
    assert s.StateIs("vacuum-gripper", "holding", PNP + "Closed") in facts  # ClosedWithPart is a Closed
    assert s.HasSkill("vacuum-gripper", PNP + "CanGrip") in facts  # implied by the class, then a super-skill


def test_leaves_follows_code_generation(device) -> None:
    k = service.knowledge()
    facts = set(device_facts(device("robot"), k.taxonomy, [k.process("pick")]))
    assert s.Leaves("pick", "robot", "robot", "home", "at_pose") in facts
    assert s.Leaves("pick", "robot", "robot", "at_pose", "at_pose") in facts


def test_regions_keep_their_visiting_order() -> None:
    facts = process_facts(service.knowledge().process("pick-and-place"))
    region = [a.c.rsplit("#")[-1] for a in facts if isinstance(a, s.RegionState) and a.r == "gripper"]
    assert region == ["Open", "Closed", "Open"]


def test_task_facts_carry_values_in_thousandths() -> None:
    facts = task_facts(task("bin-picking-invalid"), "t")
    assert s.ValueNum("t", 1, "grip_force", 45000) in facts
    assert s.ValueKind("t", 1, "grip_force", "integer") in facts


@pytest.mark.parametrize("value, kinds", [(True, ("boolean",)), (3, ("integer",)), (2.5, ("decimal",)),
                                          (2.0, ("decimal", "integer")), ("bracket", ("string",)),
                                          ("0 0 1 0 180 0", ("string", "pose")), ([0, 0, 1, 0, 180, 0], ("pose",)),
                                          ([1, 2], ()), ({"a": 1}, ())])
def test_value_kinds(value: object, kinds: tuple[str, ...]) -> None:
    assert value_kinds(value) == kinds


def test_milli_rounds_and_clamps() -> None:
    assert milli(0.0005) == 0 and milli(1.2345) == 1234 and milli(1e12) == 2_000_000_000 and milli("x") is None


def test_facts_are_text_clingo_reads(cell: Cell) -> None:
    k = service.knowledge()
    atoms = [a for d in cell.devices for a in device_facts(d, k.taxonomy, k.processes)]
    ctl = clingo.Control(["--warn=none"])
    ctl.add("base", [], program(atoms))
    ctl.ground([("base", [])])
    kinds = {(type(a).asp, len(type(a)._fields)): type(a) for a in atoms}
    read = [kinds[(s.symbol.name, len(s.symbol.arguments))].from_symbol(s.symbol) for s in ctl.symbolic_atoms]
    assert len(atoms) > 100
    assert sorted(map(str, read)) == sorted(map(str, set(atoms)))  # each fact read back as itself, none lost
