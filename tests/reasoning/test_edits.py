"""The edits of a repair are read from repair.lp's ``edit/1`` terms in one place, typed."""

from __future__ import annotations

import clingo
import pytest

from plugnproduce.errors import EncodingError
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.schema import edits
from plugnproduce.reasoning.asp.terms import decode

TERMS = {
    'insert(3,1,"scan_bin")': edits.Insert(3, 1, "scan_bin"),
    "remove(2)": edits.Remove(2),
    "swap(4)": edits.Swap(4),
    'rebind(2,"gripper","g2")': edits.Rebind(2, "gripper", "g2"),
    'bind(1,"robot","r1")': edits.Bind(1, "robot", "r1"),
    'unbind(5,"camera")': edits.Unbind(5, "camera"),
    'reset(2,"force")': edits.Reset(2, "force"),
    'add("vacuum \\"v2\\"")': edits.Add('vacuum "v2"'),
}


@pytest.mark.parametrize("text", TERMS)
def test_a_models_edit_is_read_as_its_typed_edit_and_written_back_as_clingo_wrote_it(text: str) -> None:
    model = decode([clingo.parse_term(f"edit({text})")])
    (edit,) = model[s.Edit]
    assert edit.e == TERMS[text]
    assert edits.edit_text(edit.e) == str(clingo.parse_term(text))
    assert edit.text() == f"edit({text})"


def test_a_windows_edit_is_moved_to_the_whole_tasks_step_and_an_added_device_stays() -> None:
    assert edits.Rebind(2, "gripper", "g2").shifted(10) == edits.Rebind(12, "gripper", "g2")
    assert edits.Add("v2").shifted(10) == edits.Add("v2")


@pytest.mark.parametrize("text", ['paint(2,"red")', "remove(2,3)", 'remove("two")', "remove"])
def test_an_edit_of_no_known_kind_is_an_error_of_the_encodings_naming_it(text: str) -> None:
    with pytest.raises(EncodingError, match=r"repair\.lp shows an (unknown )?edit"):
        decode([clingo.parse_term(f"edit({text})")])[s.Edit]
