"""The HTTP API and tasks with named steps, data links and loops (the until-empty bin-picking task)."""

from __future__ import annotations

import httpx
import pytest

from plugnproduce import service

YAML = {"content-type": "application/yaml"}
UNTIL_EMPTY = service.builtin("tasks", "bin-picking-until-empty.yaml")


async def _until_empty(client: httpx.AsyncClient) -> dict[str, object]:
    res = await client.post("/api/task/import?filename=until-empty.yaml", content=UNTIL_EMPTY.read_bytes(),
                            headers=YAML)
    assert res.status_code == 200, res.text
    task: dict[str, object] = res.json()
    return task


async def test_processes_offer_their_outputs_and_outcomes(client: httpx.AsyncClient) -> None:
    processes = {p["command"]: p for p in (await client.get("/api/processes")).json()}
    localize = processes["localize-part"]
    pose = next(o for o in localize["outputs"] if o["name"] == "part_pose")
    assert pose["datatype"] == "pose"
    assert "BinEmpty" in localize["outcomes"]
    assert processes["place"]["outputs"] == [] and processes["place"]["outcomes"] == []


async def test_the_until_empty_task_imports_as_one_loop_with_its_link(client: httpx.AsyncClient) -> None:
    task = await _until_empty(client)
    steps = task["steps"]
    assert isinstance(steps, list) and len(steps) == 1
    loop = steps[0]["loop"]
    assert (loop["until"], loop["max"]) == ("BinEmpty", 100)
    assert [s["command"] for s in loop["steps"]] == ["localize-part", "pick", "place"]
    assert loop["steps"][0]["name"] == "localize"
    assert loop["steps"][1]["params"]["pick_pose"] == {"from": "localize", "output": "part_pose"}


async def test_the_until_empty_task_round_trips_and_is_plausible(client: httpx.AsyncClient) -> None:
    task = await _until_empty(client)
    text = (await client.post("/api/task/export", json=task)).text
    back = await client.post("/api/task/import", content=text.encode(), headers=YAML)
    assert back.json() == task
    check = (await client.post("/api/task/check", json=task)).json()
    assert check["plausible"] is True, check["problems"]


async def test_a_link_to_a_later_step_is_a_problem_at_its_row(client: httpx.AsyncClient) -> None:
    task = await _until_empty(client)
    body = task["steps"][0]["loop"]["steps"]  # type: ignore[index]
    body[0], body[1] = body[1], body[0]  # pick before the step it takes its pose from
    check = (await client.post("/api/task/check", json=task)).json()
    assert check["plausible"] is False
    problem = next(p for p in check["problems"] if p["kind"] == "bad_link")
    assert (problem["row"], problem["parameter"]) == (0, "pick_pose")
    assert "comes after it" in problem["text"]


async def test_a_loop_until_an_outcome_no_step_gives_names_the_loop(client: httpx.AsyncClient) -> None:
    task = await _until_empty(client)
    task["steps"][0]["loop"]["until"] = "PartFound"  # type: ignore[index]
    task["steps"][0]["loop"]["steps"] = task["steps"][0]["loop"]["steps"][2:]  # type: ignore[index]
    result = (await client.post("/api/task/validate", json=task)).json()
    assert result["valid"] is False
    assert any("PartFound" in p["message"] and p["row"] == 0 for p in result["problems"])


@pytest.mark.parametrize(("change", "detail"), [
    ({"repeat": 2}, "a task with a loop cannot also repeat"),
    ({"steps": [{"loop": {"steps": [{"command": "place"}]}}]}, "a loop needs a way out"),
    ({"steps": [{"name": "a", "command": "place"}, {"name": "a", "command": "place"}]}, "step name 'a' appears twice"),
    ({"steps": [{"command": "pick", "params": {"pick_pose": {"from": "a"}}}]}, "steps[0].params.pick_pose: a parameter"),
])
async def test_a_malformed_loop_or_link_is_refused_with_its_finding(client: httpx.AsyncClient,
                                                                    change: dict[str, object], detail: str) -> None:
    task = {**(await _until_empty(client)), **change}
    res = await client.post("/api/task/check", json=task)
    assert res.status_code == 422
    assert detail in res.json()["detail"]


async def test_a_loop_inside_a_loop_imports_nested_as_written(client: httpx.AsyncClient) -> None:
    rounds = service.builtin("tasks", "bin-picking-in-rounds.yaml")
    res = await client.post("/api/task/import?filename=rounds.yaml", content=rounds.read_bytes(), headers=YAML)
    assert res.status_code == 200, res.text
    [outer] = res.json()["steps"]
    assert outer["loop"]["max"] == 3
    inner, home = outer["loop"]["steps"]
    assert (inner["loop"]["until"], inner["loop"]["max"]) == ("BinEmpty", 3)
    assert [s["command"] for s in inner["loop"]["steps"]] == ["localize-part", "pick", "place"]
    assert home["command"] == "move-to"
