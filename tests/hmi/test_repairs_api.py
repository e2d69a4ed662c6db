"""The HMI's repairs are the command line's: the same repairs, in the same documented order, with the devices'
own limits kept and the values written with units kept; and the page says that order."""

from __future__ import annotations

import json
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import httpx
import pytest
import yaml
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.cli import app
from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app
from tests.hmi.conftest import TOKEN

LIBRARIES = Path(__file__).parents[1] / "data" / "libraries"
WITHOUT_GRIPPER = LIBRARIES / "gentle-tending" / "cells" / "tending-without-gripper.yaml"
GENTLE_TASK = LIBRARIES / "gentle-tending" / "tasks" / "gentle-tending.yaml"
BUILTIN_DEVICES = service.builtin("devices")
BIN_PICKING = service.builtin("cells", "bin-picking.yaml")
UNITS = """task: units
steps:
  - command: bin-pick
    params: {grip_force: "80 N", speed: "40 %"}
  - command: bin-pick
    params: {grip_force: 80, speed: 40}
  - command: place
"""


def _cli(*args: str, exit_code: int = 0) -> dict[str, Any]:
    result = CliRunner().invoke(app, [*args, "--json"])
    assert result.exit_code == exit_code, result.output
    answer: dict[str, Any] = json.loads(result.stdout)
    return answer


def _shown(repairs: list[dict[str, Any]]) -> list[tuple[object, ...]]:
    """What a user reads of each repair: its rank, cost, edits, devices bought and side effects."""
    return [(r["rank"], r["cost"], [e["text"] for e in r["edits"]], r["added_devices"],
             [x["text"] for x in r["side_effects"]]) for r in repairs]


@pytest.fixture()
async def tending(tmp_path: Path) -> AsyncIterator[httpx.AsyncClient]:
    """The HMI over the library's cell without a gripper (simulated), repairs buying from the built-in devices."""
    k = service.knowledge_for_cell(WITHOUT_GRIPPER)
    catalogue = service.catalogue(BUILTIN_DEVICES, k)
    source = SimulatedCellSource(service.cell(WITHOUT_GRIPPER, k), catalogue, knowledge=k)
    application = create_app(source, ExecutorRunner(source, tmp_path / "runs", k), TOKEN, catalogue=catalogue,
                             knowledge=k)
    transport = httpx.ASGITransport(app=application, client=("127.0.0.1", 50000))
    async with application.router.lifespan_context(application):
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as client:
            yield client


async def test_a_purchase_keeps_the_bought_devices_limits_as_on_the_command_line(
        tending: httpx.AsyncClient) -> None:
    task = yaml.safe_load(GENTLE_TASK.read_text(encoding="utf-8"))
    res = await tending.post("/api/task/repair?top=3", json=task)
    assert res.status_code == 200, res.text
    ours = res.json()["repairs"]
    cli = _cli("repair", str(GENTLE_TASK), "--cell", str(WITHOUT_GRIPPER), "--catalogue", str(BUILTIN_DEVICES),
               "--top", "3")["repairs"]
    assert _shown(ours) == _shown(cli)
    assert ours[0]["added_devices"] == ["vacuum-gripper"]
    assert any("device 'vacuum-gripper' takes at least 20 kPa; the value is 15 kPa" in e["text"]
               for e in ours[0]["edits"])
    assert [r["rank"] for r in ours] == [1, 2, 3] and [r["cost"] for r in ours] == [9.09, 12, 12.09]


async def test_values_written_with_units_survive_repair_and_explain_as_on_the_command_line(
        client: httpx.AsyncClient, tmp_path: Path) -> None:
    task = yaml.safe_load(UNITS)
    repaired = (await client.post("/api/task/repair?top=3", json=task)).json()["repairs"]
    path = tmp_path / "units.yaml"
    path.write_text(UNITS, encoding="utf-8")
    k = service.knowledge()
    expected = service.assessed_repairs(path, BIN_PICKING, service.catalogue(knowledge=k), 3, k)
    assert _shown(repaired) == _shown([r.to_json() for r in expected])
    assert not any(e["kind"] == "reset" for r in repaired for e in r["edits"])
    first_steps = [r["task"]["steps"][0] for r in repaired if r["task"]["steps"][0]["command"] == "bin-pick"]
    assert first_steps and all(s["params"] == {"grip_force": "80 N", "speed": "40 %"} for s in first_steps)
    why = (await client.post("/api/task/explain?step=2", json=task)).json()
    cli = _cli("explain", str(path), "--cell", str(BIN_PICKING), "--step", "2", exit_code=1)  # a "no": a finding
    edits = [c["text"] for c in why["counterfactuals"] if c["kind"] == "edit_task"]
    assert edits == [c["text"] for c in cli["counterfactuals"] if c["kind"] == "edit_task"]
    assert "insert open-gripper before step 2 (bin-pick)" in edits and not any("reset" in e for e in edits)


async def test_the_page_says_the_order_repairs_are_ranked_in(client: httpx.AsyncClient) -> None:
    page = (await client.get("/")).text
    assert '<h3 id="repairs-h">Repairs, fewest side effects first, then cheapest</h3>' in page
    assert "cheapest first" not in page
