"""The error family: an unknown name says what it is and the nearest known names; every exception the
project raises on purpose belongs to the family, and each concept has one class name."""

from __future__ import annotations

import ast
import pickle
from pathlib import Path

import pytest

from plugnproduce.description.model import Cell
from plugnproduce.description.paths import NoPath
from plugnproduce.description.quantities.unitcache import Incompatible
from plugnproduce.description.quantities.units import UnitError, convert
from plugnproduce.errors import PlugNProduceError, UnknownName, bug_message
from plugnproduce.sim.bin import BinError

SRC = Path(__file__).parent.parent / "src" / "plugnproduce"


def test_an_unknown_name_offers_the_nearest_known_ones() -> None:
    err = UnknownName("process command", "plase", ["pick", "place", "bin-pick"])
    assert str(err) == "unknown process command 'plase'; did you mean place?"


def test_with_none_near_it_lists_the_known_names_at_most_a_dozen() -> None:
    assert str(UnknownName("device", "zz", ["robot", "gripper"], owner="cell c")) == \
        "unknown device 'zz' of cell c (known: gripper, robot)"
    many = str(UnknownName("run", "x", [f"run-{i:02}" for i in range(20)]))
    assert many.endswith("run-11, … (20 in all))") and "run-12" not in many


def test_a_detail_replaces_the_known_names() -> None:
    assert str(UnknownName("step", 9, detail="the task has steps 1 to 3")) == \
        "unknown step 9; the task has steps 1 to 3"


def test_an_unknown_name_is_a_key_error_of_the_family_and_survives_a_worker_process() -> None:
    err = UnknownName("state", "Opne", ["Open", "Closed"], owner="device gripper")
    again = pickle.loads(pickle.dumps(err))  # an HMI job raises it in a worker, the server answers it
    assert isinstance(again, PlugNProduceError) and isinstance(again, KeyError)
    assert str(again) == str(err) == "unknown state 'Opne' of device gripper; did you mean Open?"


def test_a_model_lookup_names_what_is_unknown_and_where() -> None:
    with pytest.raises(UnknownName, match=r"^unknown device 'gripr' of cell c; did you mean gripper\?$"):
        _cell_with("gripper").device("gripr")


def _cell_with(device_id: str) -> Cell:
    from plugnproduce import service

    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    return Cell("c", tuple(d for d in cell.devices if d.id == device_id))


def test_a_unit_error_is_of_the_family() -> None:
    with pytest.raises(PlugNProduceError):
        convert(1.0, "N", "m")


@pytest.mark.parametrize("cls", [NoPath, UnitError, Incompatible, BinError])
def test_the_classes_that_stood_outside_are_in_the_family(cls: type[Exception]) -> None:
    assert issubclass(cls, PlugNProduceError)


def test_a_bug_message_says_it_is_a_bug_and_where_the_traceback_is() -> None:
    assert bug_message(KeyError("x"), "/tmp/bugs.log") == (
        "error: a bug in plugnproduce, not a mistake in the input (KeyError: 'x'); the traceback is in "
        "/tmp/bugs.log: please report it with that traceback")


def _public_classes() -> dict[str, list[str]]:
    found: dict[str, list[str]] = {}
    for path in sorted(SRC.rglob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                found.setdefault(node.name, []).append(str(path.relative_to(SRC)))
    return found


@pytest.mark.parametrize("name", ["Problem", "Fault", "Path", "Step"])
def test_one_class_per_concept_name(name: str) -> None:
    defined = _public_classes().get(name, [])
    assert len(defined) <= 1, f"{name} is defined in {', '.join(defined)}"


def test_every_exception_class_is_of_the_family() -> None:
    """A class whose name ends in Error, Failed, Refused... derives from PlugNProduceError (private signals
    inside a module, ``_Refused``, are left out: they never leave it)."""
    outside = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_") and node.name != "PlugNProduceError":
                bases = {b.id if isinstance(b, ast.Name) else getattr(b, "attr", "") for b in node.bases}
                if bases & {"Exception", "ValueError", "LookupError", "KeyError", "RuntimeError", "TypeError"} \
                        and "PlugNProduceError" not in bases:
                    outside.append(f"{path.relative_to(SRC)}: {node.name}")
    assert outside == []
