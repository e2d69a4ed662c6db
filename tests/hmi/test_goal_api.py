"""The Goal view's plan of a library's goal carries the cycle time the command line estimates for it, from the
durations the library's devices declare; a device's JSON names the state concepts a goal's ``end`` may take."""

from __future__ import annotations

import json
from collections.abc import AsyncIterator
from pathlib import Path

import httpx
import pytest
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app
from tests.hmi.conftest import TOKEN

TIMED = Path(__file__).parents[1] / "data" / "libraries" / "timed-cell"
CELL = TIMED / "cells" / "timed-cell.yaml"
GOAL = TIMED / "goals" / "move-a-part.yaml"


@pytest.fixture()
async def timed(tmp_path: Path) -> AsyncIterator[httpx.AsyncClient]:
    """The HMI over the library's simulated cell."""
    k = service.knowledge_for_cell(CELL)
    source = SimulatedCellSource(service.cell(CELL, k), service.catalogue(knowledge=k), knowledge=k)
    application = create_app(source, ExecutorRunner(source, tmp_path / "runs", k), TOKEN, knowledge=k)
    transport = httpx.ASGITransport(app=application, client=("127.0.0.1", 50000))
    async with application.router.lifespan_context(application):
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as client:
            yield client


async def test_a_library_goal_s_plan_has_the_cycle_time_pnp_plan_estimates(timed: httpx.AsyncClient) -> None:
    res = await timed.post("/api/goal/plan?filename=move-a-part.yaml", content=GOAL.read_bytes(),
                           headers={"content-type": "application/yaml"})
    assert res.status_code == 200, res.text
    answer = res.json()
    cli = CliRunner().invoke(app, ["plan", str(GOAL), "--cell", str(CELL), "--json"])
    assert cli.exit_code == 0, cli.output
    assert answer["reachable"] and answer["cycle_time"] == json.loads(cli.stdout)["cycle_time"]
    estimate = answer["cycle_time"]
    assert [s["step"] for s in estimate["steps"]] == [s["step"] for s in answer["steps"]]
    assert abs(sum(s["seconds"] for s in estimate["steps"]) - estimate["total_seconds"]) < 0.002  # no loop


async def test_a_device_names_the_state_concepts_of_its_chart(timed: httpx.AsyncClient) -> None:
    devices = {d["id"]: d for d in (await timed.get("/api/cell")).json()["devices"]}
    assert {"Open", "Closed"} <= set(devices["tc-gripper"]["concepts"])
