"""Every process command a shipped cell offers, as a one-step task with each of its bindings: plausible
by the check means proved by verification (a plausible program that cannot run is a failure)."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.model import Step, Task
from plugnproduce.resources import descriptions_path

D = descriptions_path()
CELLS = sorted((D / "cells").glob("*.yaml"))
COMMANDS = sorted(p.stem for p in (D / "processes").glob("*.ttl"))
NOT_YET = {("assembly", "close-gripper"), ("assembly", "pick"), ("assembly", "pick-and-place")}
WHY_NOT_YET = ("issue 12, part 1: the check does not yet reason over device arguments, so it calls these "
               "plausible while the vacuum gripper's SuctionOn lacks its Vacuum argument; verification refutes them")


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("cell", CELLS, ids=lambda p: p.stem)
def test_an_offered_command_that_is_plausible_is_proved(cell: Path, command: str,
                                                       request: pytest.FixtureRequest) -> None:
    if (cell.stem, command) in NOT_YET:
        request.applymarker(pytest.mark.xfail(reason=WHY_NOT_YET, strict=True))
    offer = next((o for o in service.capabilities(cell).offered if o.command == command), None)
    if offer is None:
        pytest.skip(f"{cell.stem} does not offer {command}")
    refuted = []
    for binding in offer.bindings:
        task = Task.repeated(f"offered-{command}", [Step(1, command, dict(binding))], "offered.yaml")
        if service.check(task, cell).plausible:
            result = service.verify(task, cell)
            if not result.proved:
                refuted.append(f"{binding}: {result.problem}")
    assert refuted == []
