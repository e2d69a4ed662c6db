"""A value the process takes but the bound device's argument datatype refuses (a whole-newton gripper sent 45.5 N).

What ``pnp check`` calls plausible the run must hold: the executor refuses to send 45.5 to a Close that takes
``xsd:integer``, so the check tells of it at the value's line, as it tells of a value beyond the device's limits.
"""

from __future__ import annotations

import dataclasses
import re
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.batch import Configuration
from plugnproduce.cli import app
from plugnproduce.description.model import Argument
from plugnproduce.description.quantities.contracts import XSD, breach, in_contract_unit
from plugnproduce.description.quantities.ranges import OutputRange
from plugnproduce.description.tasks import Link
from plugnproduce.executor.monitor import Breach, Monitor
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.reasoning.checks.linksafety import _unproven
from tests.conftest import edit
from tests.reasoning.conftest import DESCRIPTIONS, write

ADAPTIVE = Path(__file__).parent.parent / "data" / "libraries" / "adaptive-gripper"
WHOLE = "takes a whole number; the value is 45.5"


@pytest.fixture()
def builtin_cell(tmp_path: Path) -> Path:
    """The built-in bin-picking cell whose gripper's Close takes whole newtons."""
    devices = tmp_path / "cell" / "devices"
    devices.mkdir(parents=True)
    for name in ("robot", "gripper", "sensor3d", "binpicking-pc"):
        for ext in ("ttl", "scxml"):
            shutil.copy(DESCRIPTIONS / "devices" / f"{name}.{ext}", devices)
    edit(devices / "gripper.ttl", "pnp:quantity pnp:GripForce ;\n    pnp:datatype xsd:decimal ;",
         "pnp:quantity pnp:GripForce ;\n    pnp:datatype xsd:integer ;")
    cell = tmp_path / "cell" / "cells" / "bin-picking.yaml"
    cell.parent.mkdir()
    shutil.copy(DESCRIPTIONS / "cells" / "bin-picking.yaml", cell)
    return cell


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    """The adaptive-gripper library (outside the package), its Close taking whole newtons from 10 to 60."""
    folder = Path(shutil.copytree(ADAPTIVE, tmp_path / "adaptive-gripper"))
    edit(folder / "devices" / "adaptive-gripper.ttl", "pnp:cost 2400 .",
         "pnp:cost 2400 ;\n    pnp:hasArgument dev:adaptive-gripper-force .\n\n"
         "dev:adaptive-gripper-force a pnp:RequestArgument ;\n    pnp:request \"Close\" ;\n"
         "    pnp:quantity pnp:GripForce ;\n"
         "    pnp:datatype <http://www.w3.org/2001/XMLSchema#integer> ;\n"
         "    pnp:unit \"N\" ;\n    pnp:minValue 10 ; pnp:maxValue 60 .\n")
    return folder


def _bin_picking(tmp_path: Path, grip_force: str, gripper: str = "gripper") -> Path:
    text = (DESCRIPTIONS / "tasks" / "bin-picking.yaml").read_text(encoding="utf-8")
    return write(tmp_path, f"bin-picking-{gripper}.yaml", text.replace("grip_force: 45", f"grip_force: {grip_force}")
                 .replace("gripper: gripper}", f"gripper: {gripper}}}"))


def _line_of(task: Path, needle: str) -> int:
    return next(n for n, line in enumerate(task.read_text(encoding="utf-8").splitlines(), 1) if needle in line)


def test_check_refuses_a_fraction_of_a_newton_for_a_whole_newton_gripper_at_the_values_line(
        builtin_cell: Path, tmp_path: Path) -> None:
    task = _bin_picking(tmp_path, "45.5")
    result = CliRunner().invoke(app, ["check", str(task), "--cell", str(builtin_cell)])
    assert result.exit_code == 1, result.stdout
    assert (f"{task}:{_line_of(task, 'grip_force')}: step 1 (bin-pick): parameter grip_force = 45.5 N goes to device "
            f"'gripper' with request Close, which {WHOLE}") in result.stdout
    (problem,) = service.check(task, builtin_cell).problems
    assert (problem.kind, problem.parameter, problem.device) == ("device_limit", "grip_force", "gripper")


def test_check_calls_a_whole_number_of_newtons_plausible(builtin_cell: Path, tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["check", str(_bin_picking(tmp_path, "45")), "--cell", str(builtin_cell)])
    assert result.exit_code == 0, result.stdout


def test_a_fraction_written_in_another_unit_is_judged_as_it_is_sent(builtin_cell: Path, tmp_path: Path) -> None:
    # 0.0455 kN goes out as 45.5 N; 0.045 kN as 45 N
    assert [p.kind for p in service.check(_bin_picking(tmp_path, "'0.0455 kN'"), builtin_cell).problems] == [
        "device_limit"]
    assert service.check(_bin_picking(tmp_path, "'0.045 kN'"), builtin_cell).plausible


def test_a_library_device_that_takes_whole_newtons_refuses_a_fraction(library: Path, tmp_path: Path) -> None:
    cell = library / "cells" / "bin-picking-adaptive.yaml"
    task = _bin_picking(tmp_path, "45.5", "adaptive-gripper")
    result = CliRunner().invoke(app, ["check", str(task), "--cell", str(cell), "--verbose"])
    assert result.exit_code == 1, result.stdout
    assert f"device 'adaptive-gripper' with request Close, which {WHOLE}" in result.stdout
    assert f"{library / 'devices' / 'adaptive-gripper.ttl'}:" in result.stdout  # the contract that says so
    assert service.check(_bin_picking(tmp_path, "45", "adaptive-gripper"), cell).plausible


def test_the_batch_refuses_the_fraction_as_check_does(library: Path, tmp_path: Path) -> None:
    k = service.knowledge_for_cell(library / "cells" / "bin-picking-adaptive.yaml")
    config = Configuration("adaptive", ("adaptive-gripper", "binpicking-pc", "robot", "sensor3d"))
    fraction = service.task(_bin_picking(tmp_path, "45.5", "adaptive-gripper"))
    whole = service.task(_bin_picking(tmp_path, "45", "adaptive-gripper"))
    (row,) = service.batch([config], None, [fraction, whole], workers=1, knowledge=k)
    assert row.plausible == ("bin-picking-2",)  # the second, whole-newton task (the batch numbers like names)
    assert row.purchase is not None and row.purchase.impossible is not None
    assert row.purchase.impossible == (
        "step 1 of bin-picking: device adaptive-gripper (role gripper) refuses a value sent to it by its own limits: "
        f"parameter grip_force = 45.5 N goes with request Close, which {WHOLE}; adding devices cannot cure it")


def test_repair_resets_the_fraction_to_the_default_the_device_takes(builtin_cell: Path, tmp_path: Path) -> None:
    task = _bin_picking(tmp_path, "45.5")
    best = service.repair(task, builtin_cell)[0]
    assert best.edits and {(e.kind, e.parameter) for e in best.edits} == {("reset", "grip_force")}
    assert all(e.text.endswith(f"reset parameter grip_force to its default 40 (device 'gripper' {WHOLE})")
               for e in best.edits)
    assert service.check(best.task, builtin_cell).plausible


def test_a_linked_value_is_left_to_the_run_for_a_device_that_takes_whole_numbers() -> None:
    # no device declares that an output it reports is whole, so a linked value's datatype is known only at run
    # time, where the executor's monitor refuses a fraction (tests/executor/test_monitor.py); the check says so
    whole = Argument("Close", PNP_IRI + "GripForce", datatype=XSD + "integer", unit="N", minimum=10, maximum=60)
    reported = OutputRange("force", unit="N", minimum=20, maximum=40)
    link = Link("measure", "force")
    assert _unproven([whole], reported, link, "gripper", "scale") == (
        "gripper takes a whole number; scale does not promise one for force")
    decimal = dataclasses.replace(whole, datatype=XSD + "decimal")
    assert _unproven([decimal], reported, link, "gripper", "scale").startswith("proven: ")


def test_the_run_refuses_a_fraction_known_only_at_run_time(builtin_cell: Path) -> None:
    # what a link brings (an earlier step's output) the monitor holds to the datatype before the request goes out
    monitor = Monitor(service.generate(DESCRIPTIONS / "tasks" / "bin-picking.yaml", builtin_cell).task,
                      service.cell(builtin_cell))
    refused = monitor.check(1, "gripper", "Close", {"GripForce": 45.5}, {})
    assert isinstance(refused, Breach) and refused.why == WHOLE
    assert monitor.check(1, "gripper", "Close", {"GripForce": 45}, {}) == {"GripForce": 45}


@pytest.fixture()
def decanewton_cell(builtin_cell: Path) -> Path:
    """The bin-picking cell whose gripper's Close takes whole decanewtons (2 to 10 daN): 45 N is 4.5 daN."""
    edit(builtin_cell.parent.parent / "devices" / "gripper.ttl",
         'pnp:unit "N" ;\n    pnp:minValue 20 ; pnp:maxValue 100 .',
         'pnp:unit "daN" ;\n    pnp:minValue 2 ; pnp:maxValue 10 .')
    return builtin_cell


def test_a_whole_number_of_newtons_that_is_a_fraction_of_the_devices_unit_is_refused(
        decanewton_cell: Path, tmp_path: Path) -> None:
    # 45 N is whole, but goes out as 4.5 daN to an argument that takes whole decanewtons
    task = _bin_picking(tmp_path, "45")
    result = CliRunner().invoke(app, ["check", str(task), "--cell", str(decanewton_cell)])
    assert result.exit_code == 1, result.stdout
    assert ("parameter grip_force = 45 N goes to device 'gripper' with request Close, which takes a whole number "
            "of daN; the value is 45 N (4.5 daN)") in result.stdout
    assert service.check(_bin_picking(tmp_path, "40"), decanewton_cell).plausible


def test_the_run_sends_a_converted_whole_number_as_one_and_refuses_a_fraction(decanewton_cell: Path,
                                                                              tmp_path: Path) -> None:
    generation = service.generation(_bin_picking(tmp_path, "40"), decanewton_cell)
    chart = next(c.data for c in generation.charts if c.kind == "task").decode()
    assert re.search(r'<send event="xirp.request.Close"[^>]*>\s*<param name="GripForce" expr="4"/>', chart), chart
    monitor = Monitor(generation.generated.task, service.cell(decanewton_cell))
    assert monitor.check(1, "gripper", "Close", {"GripForce": 4.0}, {}) == {"GripForce": 4}
    # a value in newtons known only at run time (a link) is judged in the unit it goes out in
    contract = service.cell(decanewton_cell).device("gripper").argument("Close", PNP_IRI + "GripForce")
    assert breach(45, "N", contract) == "takes a whole number of daN; the value is 45 N (4.5 daN)"
    assert breach(40, "N", contract) is None and in_contract_unit(40, "N", contract) == 4
