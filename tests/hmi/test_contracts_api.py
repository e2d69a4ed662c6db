"""The HTTP API tells of a value beyond a device's limits, or in a wrong unit, as a finding: never a 500."""

from __future__ import annotations

import httpx
import pytest

from tests.hmi.conftest import AUTH


def _task(value: object) -> dict[str, object]:
    return {"name": "t", "steps": [{"command": "pick", "params": {"grip_force": value}}]}


@pytest.mark.parametrize("path", ["/api/task/check", "/api/task/repair", "/api/task/generate"])
@pytest.mark.parametrize("value, kind, needle", [
    ("0.12 kN", "device_limit", "takes at most 100 N; the value is 120 N"),
    (130, "device_limit", "takes at most 100 N; the value is 130 N"),
    ("12 kg", "bad_unit", "kg cannot be converted to N"),
    ("5 N**9**9**9", "bad_unit", "unknown unit"),
])
async def test_a_value_the_gripper_cannot_take_is_a_finding_at_its_row(
        client: httpx.AsyncClient, path: str, value: object, kind: str, needle: str) -> None:
    res = await client.post(path, json=_task(value))
    assert res.status_code == 200
    body = res.json()
    assert body["plausible"] is False
    (problem,) = [p for p in body["problems"] if p["kind"] == kind]
    assert needle in problem["text"] and problem["parameter"] == "grip_force" and problem["row"] == 0


async def test_a_force_with_a_unit_in_the_limits_generates(client: httpx.AsyncClient) -> None:
    res = await client.post("/api/task/generate", json=_task("0.05 kN"))
    assert res.status_code == 200 and res.json()["plausible"] is True and res.json()["charts"]


async def test_a_run_beyond_a_device_limit_is_refused_with_the_finding(client: httpx.AsyncClient) -> None:
    res = await client.post("/api/runs", json={"task": _task("0.12 kN")}, headers=AUTH)
    assert res.status_code == 409
    assert "takes at most 100 N" in res.json()["detail"]


async def test_the_check_proves_a_lift_relative_to_a_reported_pose_as_the_cli_does(client: httpx.AsyncClient) -> None:
    steps = [{"name": "localize", "command": "localize-part"},
             {"command": "pick", "params": {"pick_pose": {"from": "localize", "output": "part_pose"},
                                            "lift_pose": {"from": "localize", "output": "part_pose",
                                                          "offset": [0, 0, 0.2, 0, 0, 0]}}}]
    res = await client.post("/api/task/check", json={"name": "t", "steps": steps})
    assert res.status_code == 200, res.text
    links = {link["parameter"]: link for link in res.json()["links"]}
    assert links["lift_pose"]["proven"] is True and "plus an offset of 0.2 m" in links["lift_pose"]["why"]


@pytest.mark.parametrize("path", ["/api/task/check", "/api/task/repair", "/api/task/generate"])
@pytest.mark.parametrize("value", ["1e308 kN", "nan N", "-inf N"])
async def test_issue_24_a_quantity_that_is_no_finite_number_is_422_not_500(
        client: httpx.AsyncClient, path: str, value: str) -> None:
    res = await client.post(path, json=_task(value))
    assert res.status_code == 422
    assert f"step 1 (pick): parameter grip_force is '{value}'" in res.json()["detail"]


@pytest.mark.parametrize("value", ["١٢٠ N", "𝟒𝟓 N"])
async def test_issue_24_unicode_digits_are_no_number_over_http_either(client: httpx.AsyncClient, value: str) -> None:
    body = (await client.post("/api/task/check", json=_task(value))).json()
    assert "problems" in body, body
    assert [(p["kind"], p["parameter"]) for p in body["problems"]] == [("bad_type", "grip_force")]
