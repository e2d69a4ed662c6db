"""Every process command a shipped cell offers, as a one-step task with each of its bindings: plausible
by the check means proved by verification, and run on the simulated cell to ``succeeded`` (a
plausible program that cannot run is a failure)."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.description.model import Step, Task
from plugnproduce.resources import descriptions_path

D = descriptions_path()
CELLS = sorted((D / "cells").glob("*.yaml"))
COMMANDS = sorted(p.stem for p in (D / "processes").glob("*.ttl"))


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("cell", CELLS, ids=lambda p: p.stem)
async def test_an_offered_command_that_is_plausible_is_proved_and_runs(cell: Path, command: str,
                                                                      tmp_path: Path) -> None:
    offer = next((o for o in service.capabilities(cell, all_bindings=True).offered if o.command == command), None)
    if offer is None:
        pytest.skip(f"{cell.stem} does not offer {command}")
    failed = []
    for n, binding in enumerate(offer.bindings):
        task = Task.repeated(f"offered-{command}", [Step(1, command, dict(binding))], "offered.yaml")
        if service.check(task, cell).plausible:
            result = service.verify(task, cell)
            if not result.proved:
                failed.append(f"{binding}: not proved: {result.problem}")
                continue
            run = await service.run_task(task, cell, simulate=True, journal=tmp_path / f"run-{n}.jsonl")
            if run.outcome != "succeeded":
                failed.append(f"{binding}: run {run.outcome}: {run.fault}")
    assert failed == []
