"""Every process command on every shipped cell, as a one-step task with each binding the cell offers: whether
it is offered, plausible as one step and proved is written in a table, and every row is asserted (a command
that stops being offered, or a binding that stops being plausible, is a failing row, never a skip). A
plausible one-step task is run on the simulated cell to ``succeeded`` (a plausible program that cannot run is
a failure)."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import controller, service
from plugnproduce.description.model import Step, Task
from plugnproduce.resources import descriptions_path

D = descriptions_path()
CELLS = sorted((D / "cells").glob("*.yaml"))
COMMANDS = sorted(p.stem for p in (D / "processes").glob("*.ttl"))

BIN_PICKING = {"gripper": "gripper", "localizer": "binpicking-pc", "robot": "robot", "sensor": "sensor3d"}
MIXED = {"gripper": "gripper", "localizer": "binpicking-pc-ua", "robot": "robot", "sensor": "sensor3d",
         "screwdriver": "screwdriver-ua"}
ASSEMBLY = {"gripper": "vacuum-gripper", "robot": "cobot", "screwdriver": "screwdriver", "machine": "cnc",
            "conveyor": "conveyor"}


def roles(cell: dict[str, str], *names: str) -> tuple[tuple[str, str], ...]:
    return tuple((n, cell[n]) for n in sorted(names))


NOT_OFFERED = None
TABLE: dict[tuple[str, str], tuple[tuple[tuple[str, str], ...], str | None, bool | None] | None] = {
    # (cell, command): None when not offered, else (binding, why it is not plausible as one step: the problem and
    # the state the gripper starts in (None: it is plausible), proved by verification (None: not plausible, so
    # not verified))
    ("assembly", "bin-pick"): NOT_OFFERED,
    ("assembly", "close-gripper"): NOT_OFFERED,
    ("assembly", "localize-part"): NOT_OFFERED,
    ("assembly", "machine-part"): (roles(ASSEMBLY, "machine"), None, True),
    ("assembly", "move-to"): (roles(ASSEMBLY, "robot"), None, True),
    ("assembly", "open-gripper"): (roles(ASSEMBLY, "gripper"), "wrong_state: released", None),  # needs it closed
    ("assembly", "pick"): NOT_OFFERED,
    ("assembly", "pick-and-place"): NOT_OFFERED,
    ("assembly", "place"): (roles(ASSEMBLY, "gripper", "robot"), "wrong_state: released", None),  # needs it closed
    ("assembly", "scan-bin"): NOT_OFFERED,
    ("assembly", "screw"): (roles(ASSEMBLY, "robot", "screwdriver"), None, True),
    ("assembly", "transport"): (roles(ASSEMBLY, "conveyor"), None, True),
    ("bin-picking", "bin-pick"): (roles(BIN_PICKING, "gripper", "localizer", "robot", "sensor"), None, True),
    ("bin-picking", "close-gripper"): (roles(BIN_PICKING, "gripper"), None, True),
    ("bin-picking", "localize-part"): (roles(BIN_PICKING, "localizer", "sensor"), None, True),
    ("bin-picking", "machine-part"): NOT_OFFERED,
    ("bin-picking", "move-to"): (roles(BIN_PICKING, "robot"), None, True),
    ("bin-picking", "open-gripper"): (roles(BIN_PICKING, "gripper"), "wrong_state: open", None),  # needs it closed
    ("bin-picking", "pick"): (roles(BIN_PICKING, "gripper", "robot"), None, True),
    ("bin-picking", "pick-and-place"): (roles(BIN_PICKING, "gripper", "robot"), None, True),
    ("bin-picking", "place"): (roles(BIN_PICKING, "gripper", "robot"), "wrong_state: open", None),  # needs it closed
    ("bin-picking", "scan-bin"): (roles(BIN_PICKING, "sensor"), None, True),
    ("bin-picking", "screw"): NOT_OFFERED,
    ("bin-picking", "transport"): NOT_OFFERED,
    ("mixed", "bin-pick"): (roles(MIXED, "gripper", "localizer", "robot", "sensor"), None, True),
    ("mixed", "close-gripper"): (roles(MIXED, "gripper"), None, True),
    ("mixed", "localize-part"): (roles(MIXED, "localizer", "sensor"), None, True),
    ("mixed", "machine-part"): NOT_OFFERED,
    ("mixed", "move-to"): (roles(MIXED, "robot"), None, True),
    ("mixed", "open-gripper"): (roles(MIXED, "gripper"), "wrong_state: open", None),  # needs it closed
    ("mixed", "pick"): (roles(MIXED, "gripper", "robot"), None, True),
    ("mixed", "pick-and-place"): (roles(MIXED, "gripper", "robot"), None, True),
    ("mixed", "place"): (roles(MIXED, "gripper", "robot"), "wrong_state: open", None),  # needs it closed
    ("mixed", "scan-bin"): (roles(MIXED, "sensor"), None, True),
    ("mixed", "screw"): (roles(MIXED, "robot", "screwdriver"), None, True),
    ("mixed", "transport"): NOT_OFFERED,
}
"""Each cell offers each command with one binding at most; a second binding would be a row of its own."""

ROWS = [(cell, command) for cell in CELLS for command in COMMANDS]


def test_the_table_has_a_row_for_every_command_on_every_shipped_cell() -> None:
    assert sorted(TABLE) == sorted((cell.stem, command) for cell, command in ROWS)


@pytest.mark.parametrize("cell", CELLS, ids=lambda p: p.stem)
def test_each_cell_offers_exactly_the_commands_and_bindings_of_the_table(cell: Path) -> None:
    offered = {o.command: tuple(tuple(sorted(dict(b).items())) for b in o.bindings)
               for o in service.capabilities(cell, all_bindings=True).offered}
    expected = {command: (row[0],) for (c, command), row in TABLE.items() if c == cell.stem and row is not None}
    assert offered == expected


OFFERED = [(cell, command) for cell, command in ROWS if TABLE[(cell.stem, command)] is not None]


@pytest.mark.parametrize(("cell", "command"), OFFERED, ids=lambda x: x.stem if isinstance(x, Path) else x)
async def test_an_offered_binding_is_plausible_proved_and_runs_as_the_table_says(cell: Path, command: str,
                                                                                tmp_path: Path) -> None:
    row = TABLE[(cell.stem, command)]
    assert row is not None
    binding, why_not, proved = row
    task = Task.repeated(f"offered-{command}", [Step(1, command, dict(binding))], "offered.yaml")
    checked = service.check(task, cell)
    assert [f"{p.kind}: {p.state}" for p in checked.problems] == ([why_not] if why_not else [])
    if why_not is not None:
        return  # not plausible as one step: nothing to prove or run (the table says why)
    result = service.verify(task, cell)
    assert result.proved is proved, result.problem
    run = await controller.run_task(task, cell, simulate=True, journal=tmp_path / "run.jsonl")
    assert (run.outcome, run.fault) == ("succeeded", None)
