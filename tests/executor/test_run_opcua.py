"""The controller runs a task on a cell that mixes XIRP, UPnP and OPC UA, and stops an OPC UA skill safely."""

from __future__ import annotations

import asyncio
import shutil
from pathlib import Path

from plugnproduce import controller, service
from plugnproduce.executor.journal import read_journal
from plugnproduce.executor.run import TaskRun

TASK = service.builtin("tasks", "pick-and-screw.yaml")
CELL = service.builtin("cells", "mixed.yaml")
LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "opcua-glue"


async def test_the_mixed_task_runs_and_the_journal_shows_the_opc_ua_steps_with_their_values(tmp_path: Path) -> None:
    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl")
    assert report.outcome == "succeeded", report.fault
    run = read_journal(report.journal)
    assert run.start is not None and run.start["devices"]["screwdriver-ua"].startswith("opc.tcp://127.0.0.1:")
    assert {r["device"] for r in run.of_kind("command")} == {  # XIRP, XIRP, UPnP, OPC UA, OPC UA
        "robot", "gripper", "sensor3d", "binpicking-pc-ua", "screwdriver-ua"}
    sent = [(r["step"], r["command"], r.get("params")) for r in run.of_kind("command") if r["device"] == "screwdriver-ua"]
    assert [(step, command) for step, command, _ in sent] == [(4, "Start"), (8, "Reset"), (8, "Start")]
    completed = [r for r in run.of_kind("event") if r["device"] == "screwdriver-ua"]
    assert [(r["event"], r["params"]) for r in completed] == [("Completed", {"achieved_torque": 3.0})] * 2
    localized = [r for r in run.of_kind("event") if r["device"] == "binpicking-pc-ua"]  # Localize's output arguments
    assert [r["params"]["part_pose"] for r in localized] == [[0.4, 0.1, 0.05, 0.0, 180.0, 0.0]] * 2
    values = [(r["value"], r.get("produced"), r["device"]) for r in run.of_kind("value") if "produced" in r]
    assert values == [("localize.part_pose", [0.4, 0.1, 0.05, 0.0, 180.0, 0.0], "binpicking-pc-ua")] * 2
    assert report.device_states["screwdriver-ua"] == "Complete"


async def test_a_stop_during_the_screwing_skill_sends_its_stop(tmp_path: Path) -> None:
    def stop_once_screwing(record: dict[str, object]) -> None:  # Start was answered: the skill runs
        if record["kind"] == "state" and (record["device"], record["state"]) == ("screwdriver-ua", "Execute"):
            runs[0].stop()

    runs: list[TaskRun] = []
    report = await controller.run_task(TASK, CELL, simulate=True, journal=tmp_path / "run.jsonl",
                                    observer=stop_once_screwing, started=runs.append)
    assert report.outcome == "stopped" and report.fault is not None and report.fault.kind == "stopped"
    stops = {r["device"]: r for r in read_journal(report.journal).of_kind("stop")}
    assert (stops["screwdriver-ua"]["request"], stops["screwdriver-ua"]["answer"]) == ("Stop", "accepted")
    assert stops["screwdriver-ua"]["state"] in {"Stopping", "Stopped"}


async def test_a_library_written_outside_the_package_runs_its_opc_ua_device(tmp_path: Path) -> None:
    """A user's glue dispenser over OPC UA: its own terms (bead length, glue kind) become method arguments."""
    library = shutil.copytree(LIBRARY, tmp_path / "opcua-glue")
    report = await controller.run_task(library / "tasks" / "opcua-glue.yaml", library / "cells" / "opcua-glue-cell.yaml",
                                    simulate=True, journal=tmp_path / "run.jsonl")
    assert report.outcome == "succeeded", report.fault
    run = read_journal(report.journal)
    sent = [(r["device"], r["command"], r["params"]) for r in run.of_kind("command")]
    assert ("dispenser", "Dispense", {"BeadLength": 120, "GlueKind": "polyurethane"}) in sent
    assert [(r["device"], r["event"]) for r in run.of_kind("event") if r["device"] == "dispenser"] \
        == [("dispenser", "bead_laid")]


async def test_an_opc_ua_device_unplugged_during_its_skill_is_lost(tmp_path: Path) -> None:
    from plugnproduce.discovery import LiveCell
    from plugnproduce.ontology.taxonomy import load_taxonomy
    from plugnproduce.protocols import upnp
    from plugnproduce.sim.cell import SimulatedCell

    cell = service.cell(CELL)
    generated = service.generate(TASK, cell).task
    network = upnp.private_network()
    async with SimulatedCell(cell, network=network) as sim, LiveCell(load_taxonomy(), network=network) as live:
        devices = await controller.find_devices(live, [d.id for d in cell.devices],
                                                controller.SIMULATED_DISCOVERY_SECONDS)

        def unplug_while_screwing(record: dict[str, object]) -> None:
            if record["kind"] == "state" and (record["device"], record["state"]) == ("screwdriver-ua", "Execute"):
                asyncio.get_running_loop().create_task(sim.unplug("screwdriver-ua"))

        report = await TaskRun(generated, devices, tmp_path / "run.jsonl", unplug_while_screwing).run()
    assert report.outcome == "failed"
    assert report.fault is not None and (report.fault.kind, report.fault.device) == ("lost", "screwdriver-ua")
    stops = {r["device"]: r for r in read_journal(report.journal).of_kind("stop")}
    assert stops["screwdriver-ua"]["answer"].startswith("no state reported")
