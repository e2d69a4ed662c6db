"""Verification on a hierarchical Device State Chart: a request written on a compound state is judged by that
transition's contract when a device inside it receives it (the runtime reports the compound state as the source)."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

from plugnproduce import service
from plugnproduce.statechart.runtime.events import EventData
from plugnproduce.verification.world import ClosedWorld, Message, Move

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "packml-screwing"


def test_a_request_on_a_superstate_is_held_to_its_contract(tmp_path: Path) -> None:
    library = Path(shutil.copytree(LIBRARY, tmp_path / "packml-screwing"))
    chart = library / "devices" / "packml-screwdriver.scxml"
    # Start moves from Idle onto a compound state Ready around it: the same request, written one level up
    chart.write_text(chart.read_text().replace(
        '<state id="Idle" pnp:concept="ToolIdle">\n        '
        '<transition event="xirp.request.Start" target="Running" pnp:accepts="Torque"/>\n      </state>',
        '<state id="Ready"><transition event="xirp.request.Start" target="Running" pnp:accepts="Torque"/>'
        '<state id="Idle" pnp:concept="ToolIdle"/></state>'))
    cell = service.cell(library / "cells" / "packml-screwing.yaml")
    screwdriver = cell.device("packml-screwdriver")
    (start,) = [t for t in screwdriver.transitions if t.event == "xirp.request.Start"]
    assert (start.source, start.origin) == ("Idle", "Ready")
    assert service.verify(library / "tasks" / "screw-twice.yaml", cell).verdict == "proved"

    generated = service.generate(library / "tasks" / "screw-twice.yaml", cell).task
    world = ClosedWorld(generated, cell)
    initial, _ = world.start()
    i = world.devices_index("packml-screwdriver")
    requests = list(initial.requests)
    requests[i] = (Message("xirp.request.Start", EventData({"Torque": 50})),)  # beyond the clutch's 10 N m
    sent = dataclasses.replace(initial, requests=tuple(requests))
    _, violation = world.apply(sent, Move("request", "packml-screwdriver", "packml-screwdriver", "xirp.request.Start"))
    assert violation is not None and violation.kind == "argument"
    assert violation.message == ("device packml-screwdriver: xirp.request.Start argument Torque is 50, beyond the "
                                 "device's contract: it takes at most 10 N m; the value is 50 N m")
