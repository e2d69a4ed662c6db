"""Runs through the Runner interface (the executor on the simulated cell), and the server-sent event stream
on a real server."""

from __future__ import annotations

import asyncio
import json
from collections.abc import AsyncIterator

import httpx
import pytest

from plugnproduce.hmi.hub import Hub
from tests.hmi.conftest import AUTH, Hmi, Served
from tests.lines import WAIT

TASK = {"name": "pick-and-place", "steps": [{"command": "pick-and-place"}, {"command": "move-to"}]}


async def _until_end(client: httpx.AsyncClient, hmi: Hmi, run_id: str) -> dict[str, object]:
    """Wait for the run to end (no polling: the runner says when)."""
    await asyncio.wait_for(hmi.runner.finished(run_id), WAIT)
    return dict((await client.get(f"/api/runs/{run_id}")).json())


async def test_a_run_walks_every_step_and_journals_it(client: httpx.AsyncClient, hmi: Hmi) -> None:
    res = await client.post("/api/runs", json={"task": TASK}, headers=AUTH)
    assert res.status_code == 202 and res.json()["status"] == "running"
    run = await _until_end(client, hmi, res.json()["run"])
    assert run["status"] == "succeeded"
    assert run["states"] == {"robot": "at_pose", "gripper": "open", "sensor3d": "ready", "binpicking-pc": "ready"}
    journal = (await client.get(f"/api/runs/{run['run']}/journal")).json()
    kinds = [r["kind"] for r in journal]
    assert kinds[0] == "start" and kinds[-1] == "end" and kinds.count("step") == 2
    assert journal[0]["speed"] == 1.0 and run["speed"] == 1.0  # the simulated devices work in real time
    assert {"device": "gripper", "command": "Close"}.items() <= next(r for r in journal if r["kind"] == "command"
                                                                       and r["device"] == "gripper").items()
    listed = (await client.get("/api/runs")).json()
    assert listed["active"] is None and listed["runs"][0]["status"] == "succeeded"
    assert listed["runs"][0]["speed"] == 1.0


async def test_a_device_lost_during_a_run_is_a_fault(client: httpx.AsyncClient, hmi: Hmi) -> None:
    hub = hmi.app.state.hub
    gripper_busy = asyncio.Event()

    def on_record(run_id: str, record: dict[str, object]) -> None:
        if record["kind"] == "command" and record["device"] == "gripper":
            gripper_busy.set()
        Hub.on_run_record(hub, run_id, record)

    hub.on_run_record = on_record
    run_id = (await client.post("/api/runs", json={"task": TASK}, headers=AUTH)).json()["run"]
    await asyncio.wait_for(gripper_busy.wait(), WAIT)
    assert (await client.delete("/api/cell/devices/gripper", headers=AUTH)).status_code == 200
    run = await _until_end(client, hmi, run_id)
    assert run["status"] == "failed"
    fault = run["faults"][0]  # type: ignore[index]
    assert (fault["fault"], fault["device"], fault["step"], fault["first"]) == ("lost", "gripper", 1, True)
    assert "command" not in [r["kind"] for r in (await client.get(f"/api/runs/{run_id}/journal")).json()
                             if r["seq"] > fault["seq"]]


async def test_a_run_can_be_stopped(client: httpx.AsyncClient) -> None:
    run_id = (await client.post("/api/runs", json={"task": TASK}, headers=AUTH)).json()["run"]
    run = (await client.post(f"/api/runs/{run_id}/stop", headers=AUTH)).json()
    assert run["status"] == "stopped" and run["end"]["reason"].endswith(": stopped by the operator")
    journal = (await client.get(f"/api/runs/{run_id}/journal")).json()
    stops = {r["device"]: r for r in journal if r["kind"] == "stop"}
    assert (stops["robot"]["request"], stops["robot"]["answer"]) == ("Halt", "accepted")
    assert journal[-1]["kind"] == "end"


async def test_the_next_run_is_planned_from_where_the_last_left_the_devices(client: httpx.AsyncClient,
                                                                            hmi: Hmi) -> None:
    close = {"name": "close", "steps": [{"command": "close-gripper"}]}
    run_id = (await client.post("/api/runs", json={"task": close}, headers=AUTH)).json()["run"]
    assert (await _until_end(client, hmi, run_id))["status"] == "succeeded"
    res = await client.post("/api/runs", json={"task": TASK}, headers=AUTH)
    assert res.status_code == 409
    detail = res.json()["detail"]
    assert "device 'gripper'" in detail and "state 'closed'" in detail and "(the state it reports)" in detail
    check = (await client.post("/api/task/check", json=TASK, headers=AUTH)).json()
    assert not check["plausible"] and "(the state it reports)" in check["problems"][0]["text"]
    repair = (await client.post("/api/task/repair", json=TASK, headers=AUTH)).json()
    assert [e["text"] for e in repair["repairs"][0]["edits"]] == ["insert open-gripper before step 1 (pick-and-place)"]


async def test_a_second_run_waits_for_the_first(client: httpx.AsyncClient) -> None:
    first = (await client.post("/api/runs", json={"task": TASK}, headers=AUTH)).json()["run"]
    res = await client.post("/api/runs", json={"task": TASK}, headers=AUTH)
    assert res.status_code == 409 and res.json()["detail"] == f"error: run {first} is still running; stop it first"


async def test_an_implausible_task_does_not_start(client: httpx.AsyncClient) -> None:
    task = {"name": "t", "steps": [{"command": "pick"}, {"command": "pick"}]}
    res = await client.post("/api/runs", json={"task": task}, headers=AUTH)
    assert res.status_code == 409
    assert res.json()["detail"].startswith("error: task 't' cannot run in cell 'bin-picking': step 2 (pick):")


async def test_an_unknown_run_is_404(client: httpx.AsyncClient) -> None:
    res = await client.get("/api/runs/nope")
    assert res.status_code == 404 and res.json()["detail"] == "error: unknown run 'nope'"


async def _events(response: httpx.Response) -> AsyncIterator[tuple[str, dict[str, object]]]:
    event = ""
    async for line in response.aiter_lines():
        if line.startswith("event: "):
            event = line[7:]
        elif line.startswith("data: "):
            yield event, json.loads(line[6:])


async def _next(events: AsyncIterator[tuple[str, dict[str, object]]], name: str) -> dict[str, object]:
    async for event, data in events:
        if event == name:
            return data
    raise AssertionError(f"the stream ended before a {name!r} event")


async def test_unplug_reaches_the_event_stream(served: Served) -> None:
    # How soon is measured by bench/bench_discovery.py; here only that it comes (within a generous bound).
    async with httpx.AsyncClient(base_url=served.url, timeout=60) as client:
        async with client.stream("GET", "/events") as response:
            assert response.headers["content-type"].startswith("text/event-stream")
            events = _events(response)
            first = await _next(events, "cell")
            assert "pick" in {o["command"] for o in first["commands"]["offered"]}  # type: ignore[index]
            assert (await client.delete("/api/cell/devices/gripper", headers=AUTH)).status_code == 200
            change = await asyncio.wait_for(_next(events, "cell"), 60)
            assert change["change"] == {"kind": "unplug", "device": "gripper", "reason": "", "url": None}
            assert "pick" not in {o["command"] for o in change["commands"]["offered"]}  # type: ignore[index]
            assert "gripper" not in {d["id"] for d in change["cell"]["devices"]}  # type: ignore[index]
            await events.aclose()


async def test_run_progress_reaches_the_event_stream(served: Served) -> None:
    async with httpx.AsyncClient(base_url=served.url, timeout=60) as client:
        async with client.stream("GET", "/events") as response:
            events = _events(response)
            await _next(events, "cell")
            run_id = (await client.post("/api/runs", json={"task": TASK}, headers=AUTH)).json()["run"]
            seen: list[str] = []
            async for event, data in events:
                if event == "run":
                    assert data["run"] == run_id
                    record = data["record"]
                    seen.append(record["kind"])  # type: ignore[index]
                    if record["kind"] == "end":  # type: ignore[index]
                        assert record["outcome"] == "succeeded"  # type: ignore[index]
                        break
            assert seen[0] == "start" and "step" in seen and "state" in seen
            await events.aclose()


@pytest.mark.parametrize("path", ["/", "/static/js/main.js", "/static/style.css"])
def test_the_page_is_served_with_a_strict_policy(served: Served, path: str) -> None:
    res = httpx.get(served.url + path)
    assert res.status_code == 200
    assert "script-src 'self'" in res.headers["content-security-policy"]
