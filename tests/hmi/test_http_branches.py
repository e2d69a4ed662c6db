"""The HTTP API and tasks with branches on a step's outcome: they travel as the task file nests them, and
each finding names the editor row of its step (a branch's steps counted after their step) and its path."""

from __future__ import annotations

import httpx
import pytest

YAML = {"content-type": "application/yaml"}

BRANCHING = b"""\
task: bin-picking-branch
steps:
  - loop:
      until: BinEmpty
      max: 100
      steps:
        - name: localize
          command: localize-part
          on:
            PartFound:
              - command: pick
                params:
                  pick_pose: {from: localize, output: part_pose}
                  grip_force: 45
              - command: place
                params: {speed: 80}
  - command: scan-bin
"""


async def _branching(client: httpx.AsyncClient) -> dict[str, object]:
    res = await client.post("/api/task/import?filename=branch.yaml", content=BRANCHING, headers=YAML)
    assert res.status_code == 200, res.text
    task: dict[str, object] = res.json()
    return task


async def test_a_branch_imports_under_its_step_and_round_trips(client: httpx.AsyncClient) -> None:
    task = await _branching(client)
    localize = task["steps"][0]["loop"]["steps"][0]  # type: ignore[index]
    assert [s["command"] for s in localize["on"]["PartFound"]] == ["pick", "place"]
    assert task["steps"][1] == {"command": "scan-bin", "bind": {}, "params": {}}  # type: ignore[index]
    text = (await client.post("/api/task/export", json=task)).text
    assert "PartFound:" in text
    back = await client.post("/api/task/import", content=text.encode(), headers=YAML)
    assert back.json() == task


async def test_a_value_out_of_range_in_a_branch_is_found_at_its_row(client: httpx.AsyncClient) -> None:
    task = await _branching(client)
    task["steps"][0]["loop"]["steps"][0]["on"]["PartFound"][1]["params"]["speed"] = 900  # type: ignore[index]
    result = (await client.post("/api/task/validate", json=task)).json()
    assert result["valid"] is False
    rows = {(p["row"], p["field"]) for p in result["problems"]}
    assert rows == {(2, "steps[2].params.speed")}  # localize is row 0, pick row 1, place row 2


async def test_a_finding_in_a_branch_names_its_row_and_path(client: httpx.AsyncClient) -> None:
    task = await _branching(client)
    branch = task["steps"][0]["loop"]["steps"][0]["on"]["PartFound"]  # type: ignore[index]
    branch.insert(1, dict(branch[0]))  # a second pick while the gripper holds the part
    check = (await client.post("/api/task/check", json=task)).json()
    assert check["plausible"] is False
    first = next(p for p in check["problems"] if p["row"] == 2)
    assert first["path"].startswith("loop iteration 1, branch PartFound at step 1")


@pytest.mark.parametrize(("on", "detail"), [
    ({}, "on maps outcomes to the steps"),
    ({"PartFound": []}, "steps[0].on.PartFound: list should have at least 1 item"),
])
async def test_a_malformed_branch_is_refused_with_one_line(client: httpx.AsyncClient, on: dict[str, object],
                                                           detail: str) -> None:
    task = {"name": "t", "steps": [{"command": "localize-part", "on": on}]}
    res = await client.post("/api/task/check", json=task)
    assert res.status_code == 422
    assert detail in res.text


async def test_a_loop_that_goes_on_while_an_outcome_comes_round_trips(client: httpx.AsyncClient) -> None:
    text = b"task: t\nsteps:\n  - loop:\n      while: PartFound\n      max: 5\n      steps:\n        - command: localize-part\n"
    task = (await client.post("/api/task/import", content=text, headers=YAML)).json()
    assert {k: v for k, v in task["steps"][0]["loop"].items() if k != "steps"} == {"while": "PartFound", "max": 5}
    result = (await client.post("/api/task/validate", json=task)).json()
    assert result["valid"] is True, result["problems"]
    back = (await client.post("/api/task/export", json=task)).text
    assert (await client.post("/api/task/import", content=back.encode(), headers=YAML)).json() == task


async def test_a_branch_in_a_branch_counts_its_rows_as_written(client: httpx.AsyncClient) -> None:
    inner = {"command": "localize-part", "on": {"BinEmpty": [{"command": "place", "params": {"speed": 900}}]}}
    task = {"name": "t", "steps": [{"name": "localize", "command": "localize-part", "on": {
        "PartFound": [{"command": "scan-bin"}, inner]}}, {"command": "scan-bin"}]}
    exported = (await client.post("/api/task/export", json=task)).text
    back = (await client.post("/api/task/import", content=exported.encode(), headers=YAML)).json()
    assert back["steps"][0]["on"]["PartFound"][1]["on"]["BinEmpty"][0]["command"] == "place"
    result = (await client.post("/api/task/validate", json=task)).json()
    assert {(p["row"], p["field"]) for p in result["problems"]} == {(3, "steps[3].params.speed")}


async def test_a_process_offers_the_outcomes_a_branch_may_name_with_the_ones_they_cover(
        client: httpx.AsyncClient) -> None:
    processes = {p["command"]: p for p in (await client.get("/api/processes")).json()}
    choices = {c["outcome"]: c["covers"] for c in processes["localize-part"]["outcome_choices"]}
    assert choices == {"PartFound": ["PartFound"], "BinEmpty": ["BinEmpty"], "NoPartFound": ["BinEmpty"]}
    assert processes["pick"]["outcome_choices"] == []
