"""The HMI's HTTP API in process: the cell, processes, tasks, charts, errors and authentication."""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys
from collections.abc import AsyncIterator

import httpx
import pytest
import yaml

from plugnproduce import service
from tests.hmi.conftest import AUTH, Hmi, Served
from tests.lines import WAIT

BIN_PICK = {"command": "bin-pick", "params": {"grip_force": 45, "exposure": 25}}
PLACE = {"command": "place", "params": {"place_pose": [0.6, -0.2, 0.1, 0, 180, 0], "speed": 80}}
TASK = {"name": "bin-picking", "repeat": 3, "steps": [BIN_PICK, PLACE]}
INVALID = {"name": "bin-picking-invalid", "steps": [BIN_PICK, BIN_PICK, {"command": "place"}]}


async def test_openapi_describes_every_endpoint(client: httpx.AsyncClient) -> None:
    paths = (await client.get("/openapi.json")).json()["paths"]
    for path in ("/api/cell", "/api/commands", "/api/commands/{command}/explanation", "/api/catalogue",
                 "/api/processes", "/api/task/validate", "/api/task/check", "/api/task/repair", "/api/task/explain",
                 "/api/task/generate", "/api/task/export", "/api/task/import", "/api/charts/device/{device_id}.svg",
                 "/api/runs", "/api/runs/{run_id}/stop", "/api/runs/{run_id}/journal", "/events"):
        assert path in paths


async def test_cell_shows_each_device_with_class_skills_protocol_and_state(client: httpx.AsyncClient) -> None:
    cell = (await client.get("/api/cell")).json()
    gripper = next(d for d in cell["devices"] if d["id"] == "gripper")
    assert cell["name"] == "bin-picking" and cell["pluggable"] is True
    assert gripper["classes"] == ["parallel gripper"]
    assert "can grip" in gripper["skills"]
    assert (gripper["protocol"], gripper["state"]) == ("xirp", "open")
    assert [d["id"] for d in cell["devices"]] == ["binpicking-pc", "gripper", "robot", "sensor3d"]  # as discovery sorts them


async def test_processes_carry_what_the_dialogs_need(client: httpx.AsyncClient) -> None:
    pick = (await client.get("/api/processes/pick")).json()
    force = next(p for p in pick["parameters"] if p["name"] == "grip_force")
    assert {k: force[k] for k in ("datatype", "unit", "min", "max", "default", "role")} == {
        "datatype": "decimal", "unit": "N", "min": 10, "max": 140, "default": 40, "role": "gripper"}
    pose = next(p for p in pick["parameters"] if p["name"] == "pick_pose")
    assert pose["datatype"] == "pose" and len(pose["default"]) == 6
    assert {r["name"] for r in pick["roles"]} == {"robot", "gripper"}


async def test_catalogue_marks_the_devices_in_the_cell(client: httpx.AsyncClient) -> None:
    catalogue = {d["id"]: d["in_cell"] for d in (await client.get("/api/catalogue")).json()}
    assert catalogue["gripper"] is True and catalogue["vacuum-gripper"] is False


@pytest.mark.parametrize(("method", "path", "body"), [
    ("POST", "/api/cell/devices", {"device": "camera"}),
    ("DELETE", "/api/cell/devices/gripper", None),
    ("POST", "/api/runs", {"task": TASK}),
    ("POST", "/api/runs/any/stop", None),
])
async def test_a_change_without_the_token_is_refused(client: httpx.AsyncClient, hmi: Hmi, method: str, path: str,
                                                     body: dict[str, object] | None) -> None:
    res = await client.request(method, path, json=body)
    assert res.status_code == 401
    assert res.headers["www-authenticate"].startswith("Bearer")
    assert "bearer token" in res.json()["detail"]
    assert [d.id for d in hmi.source.cell.devices] == ["binpicking-pc", "gripper", "robot", "sensor3d"]


async def test_a_wrong_token_is_refused(client: httpx.AsyncClient) -> None:
    res = await client.delete("/api/cell/devices/gripper", headers={"Authorization": "Bearer not-the-token"})
    assert res.status_code == 401 and res.json()["detail"].startswith("wrong bearer token")


async def test_reads_from_another_host_need_the_token(hmi: Hmi) -> None:
    transport = httpx.ASGITransport(app=hmi.app, client=("192.0.2.7", 40000))
    async with hmi.app.router.lifespan_context(hmi.app), httpx.AsyncClient(
            transport=transport, base_url="http://controller") as remote:
        assert (await remote.get("/api/cell")).status_code == 401
        assert (await remote.get("/api/cell", headers=AUTH)).status_code == 200


@pytest.mark.parametrize(("body", "status", "detail"), [
    ({"name": "t", "steps": [{"params": {}}]}, 422, "steps[0].command: field required"),
    ({"name": "t", "steps": []}, 422, "steps: list should have at least 1 item"),
    ({"steps": [{"command": "pick"}]}, 422, "name: field required"),
    ({"name": "t", "repeat": 0, "steps": [{"command": "pick"}]}, 422, "repeat: input should be greater than or equal to 1"),
    ({"name": "t", "steps": [{"command": "pick", "speed": 3}]}, 422, "steps[0].speed: extra inputs are not permitted"),
    ({"name": "t", "steps": [{"command": "pick", "params": {"grip_force": {"n": 1}}}]}, 422,
     "steps[0].params.grip_force: a parameter value is a number, text, true or false, a pose"),
    ({"name": "t", "steps": [{"command": "pick", "bind": {"robot": 3}}]}, 422,
     "steps[0].bind.robot: input should be a valid string"),
])
async def test_a_malformed_task_names_the_field_and_the_reason(client: httpx.AsyncClient, body: dict[str, object],
                                                               status: int, detail: str) -> None:
    res = await client.post("/api/task/validate", json=body)
    assert res.status_code == status
    assert res.json()["detail"].startswith(detail)
    assert "\n" not in res.json()["detail"]


async def test_a_body_that_is_not_json_is_a_bad_request(client: httpx.AsyncClient) -> None:
    res = await client.post("/api/task/check", content=b"{steps: [", headers={"content-type": "application/json"})
    assert res.status_code == 400
    assert res.json()["detail"].startswith("body: not valid JSON at character 1")


async def test_validate_gives_the_shape_message_at_the_parameter(client: httpx.AsyncClient) -> None:
    task = {"name": "t", "steps": [{"command": "pick", "params": {"grip_force": 500, "speed": "fast"}}]}
    result = (await client.post("/api/task/validate", json=task)).json()
    assert result["valid"] is False
    by_field = {p["field"]: p["message"] for p in result["problems"]}
    assert by_field["steps[0].params.grip_force"] == \
        "step 1: parameter 'grip_force' is 500 N; expected a value from 10 to 140 N"
    assert by_field["steps[0].params.speed"] == "step 1: parameter 'speed' takes a number; found fast"


async def test_validate_accepts_the_bin_picking_task(client: httpx.AsyncClient) -> None:
    assert (await client.post("/api/task/validate", json=TASK)).json() == {"valid": True, "problems": []}


YAML = {"content-type": "application/yaml"}


async def test_yaml_export_and_import_round_trip(client: httpx.AsyncClient) -> None:
    res = await client.post("/api/task/export", json=TASK)
    assert res.headers["content-type"].startswith("application/yaml")
    assert yaml.safe_load(res.text)["repeat"] == 3
    back = await client.post("/api/task/import", content=res.text.encode(), headers={"content-type": "application/yaml"})
    assert back.json() == {"description": "", **TASK, "steps": [{**s, "bind": {}} for s in TASK["steps"]]}


async def test_yaml_import_errors_name_the_file_and_line(client: httpx.AsyncClient) -> None:
    text = b"task: t\nsteps:\n  - command: pick\n    speed: 3\n"
    res = await client.post("/api/task/import?filename=mine.yaml", content=text, headers=YAML)
    assert res.status_code == 400
    assert res.json()["detail"] == "mine.yaml:4: step: unknown key 'speed'; expected one of bind, command, name, on, params"


async def test_yaml_import_refuses_aliases(client: httpx.AsyncClient) -> None:
    text = b"task: t\nsteps:\n  - &s {command: pick}\n  - *s\n"
    res = await client.post("/api/task/import", content=text, headers=YAML)
    assert res.status_code == 400 and res.json()["detail"].startswith("task.yaml:")


@pytest.mark.parametrize("kind", ["text/plain", "application/x-www-form-urlencoded", "multipart/form-data", None])
async def test_yaml_import_refuses_what_a_cross_site_form_could_send(client: httpx.AsyncClient, kind: str | None) -> None:
    headers = {"content-type": kind} if kind else {}
    res = await client.post("/api/task/import", content=b"task: t\nsteps:\n  - command: pick\n", headers=headers)
    assert res.status_code == 415 and "send the task as application/yaml" in res.json()["detail"]


@pytest.mark.parametrize("kind", ["application/yaml; charset=utf-8", "Application/YAML", " text/x-yaml ;q=1"])
async def test_yaml_import_takes_each_spelling_of_a_yaml_type(client: httpx.AsyncClient, kind: str) -> None:
    """Media types are case-insensitive and may carry parameters (RFC 9110): each is YAML all the same."""
    res = await client.post("/api/task/import", content=b"task: t\nsteps:\n  - command: pick\n",
                            headers={"content-type": kind})
    assert res.status_code == 200 and res.json()["name"] == "t"


async def test_an_oversized_chunked_body_is_refused_as_it_streams(client: httpx.AsyncClient) -> None:
    async def chunks() -> AsyncIterator[bytes]:
        for _ in range(200):  # 12.5 MiB in all, with no content-length
            yield b" " * 65536

    res = await client.post("/api/task/check", content=chunks(), headers={"content-type": "application/json"})
    assert res.status_code == 413 and "larger than the 4194304 bytes accepted" in res.json()["detail"]


async def test_an_oversized_declared_body_is_refused_before_it_is_read(client: httpx.AsyncClient) -> None:
    res = await client.post("/api/task/import", content=b"x" * (5 * 1024 * 1024), headers=YAML)
    assert res.status_code == 413


async def test_device_and_process_pictures_are_svg(client: httpx.AsyncClient) -> None:
    for path in ("/api/charts/device/gripper.svg", "/api/charts/process/pick.svg"):
        res = await client.get(path)
        assert res.status_code == 200 and res.headers["content-type"] == "image/svg+xml"
        assert b"<svg" in res.content


async def test_unknown_names_get_the_cli_message(client: httpx.AsyncClient) -> None:
    res = await client.get("/api/charts/process/nope.svg")
    assert res.status_code == 404
    assert res.json()["detail"].startswith("error: unknown process command 'nope' (known: bin-pick,")


# ------------------------------------------------------------------ with the reasoner


async def test_the_bin_picking_cell_offers_pick_place_pick_and_place_and_bin_pick(client: httpx.AsyncClient) -> None:
    offered = {o["command"] for o in (await client.get("/api/commands")).json()["offered"]}
    assert {"pick", "place", "pick-and-place", "bin-pick"} <= offered


async def test_a_command_not_offered_is_explained(client: httpx.AsyncClient) -> None:
    ex = (await client.get("/api/commands/screw/explanation")).json()
    assert ex["offered"] is False
    assert any("pnp:CanScrew" in r["text"] for r in ex["reasons"])


async def test_the_explanation_carries_the_derivation_and_the_counterfactuals(client: httpx.AsyncClient) -> None:
    ex = (await client.get("/api/commands/screw/explanation")).json()
    assert ex["derivation"]["text"] == "screw is not offered in cell 'bin-picking': some role cannot be filled"
    # either catalogue screwdriver turns the answer around: the XIRP one and the OPC UA nutrunner
    assert [c["devices"] for c in ex["counterfactuals"]] == [["screwdriver"], ["screwdriver-ua"]]


async def test_a_source_line_an_explanation_cites_is_served(client: httpx.AsyncClient) -> None:
    ex = (await client.get("/api/commands/screw/explanation")).json()
    file, line = ex["derivation"]["where"].rsplit(":", 1)
    src = (await client.get("/api/source", params={"file": file, "line": line})).json()
    assert src["name"] == "screw.ttl" and any(x["number"] == int(line) and "proc:screw" in x["text"]
                                              for x in src["lines"])


async def test_no_other_file_is_served_as_a_source(client: httpx.AsyncClient, tmp_path) -> None:
    secret = tmp_path / "secret.ttl"
    secret.write_text("secret\n")
    for file in (str(secret), "/etc/passwd", str(service.builtin("cells", "bin-picking.yaml")) + "/../../x"):
        res = await client.get("/api/source", params={"file": file, "line": 1})
        assert res.status_code == 404 and res.json()["detail"] == "error: not a description file of this cell"


async def test_unplugging_the_gripper_withdraws_pick(client: httpx.AsyncClient) -> None:
    res = await client.delete("/api/cell/devices/gripper", headers=AUTH)
    assert res.status_code == 200
    assert "pick" not in {o["command"] for o in res.json()["commands"]["offered"]}
    res = await client.post("/api/cell/devices", json={"device": "gripper"}, headers=AUTH)
    assert "pick" in {o["command"] for o in res.json()["commands"]["offered"]}


async def test_plugging_a_device_twice_is_a_conflict(client: httpx.AsyncClient) -> None:
    res = await client.post("/api/cell/devices", json={"device": "gripper"}, headers=AUTH)
    assert res.status_code == 409 and res.json()["detail"] == "error: device 'gripper' is in cell 'bin-picking' already"


async def test_check_puts_the_problem_at_its_step(client: httpx.AsyncClient) -> None:
    result = (await client.post("/api/task/check", json=INVALID)).json()
    assert result["plausible"] is False
    (problem,) = result["problems"]
    assert (problem["step"], problem["row"], problem["kind"], problem["device"]) == (2, 1, "wrong_state", "gripper")


async def test_repairs_are_ranked_tasks_ready_to_apply(client: httpx.AsyncClient) -> None:
    result = (await client.post("/api/task/repair?top=2", json=INVALID)).json()
    first, second = result["repairs"]
    assert first["rank"] == 1 and first["edits"][0]["text"] == "swap step 2 (bin-pick) with step 3 (place)"
    assert second["edits"][0]["text"] == "insert open-gripper before step 2 (bin-pick)"
    assert second["solver_rank"] == 1 and [e["kind"] for e in second["side_effects"]] == ["drops_part"]
    assert [s["command"] for s in second["task"]["steps"]] == ["bin-pick", "open-gripper", "bin-pick", "place"]
    for repair in (first, second):
        fixed = (await client.post("/api/task/check", json=repair["task"])).json()
        assert fixed["plausible"] is True


async def test_explain_a_step(client: httpx.AsyncClient) -> None:
    ex = (await client.post("/api/task/explain?step=2", json=INVALID)).json()
    assert ex["plausible"] is False and any("left there by step 1" in s["text"] for s in ex["states"])
    res = await client.post("/api/task/explain?step=9", json=INVALID)
    assert res.status_code == 404 and res.json()["detail"] == "error: unknown step 9; the task has steps 1 to 3"


async def test_generate_gives_scxml_and_pictures(client: httpx.AsyncClient) -> None:
    result = (await client.post("/api/task/generate", json=TASK)).json()
    assert result["verification"]["verdict"] == "proved" and result["verification"]["states"] > 0
    names = [c["name"] for c in result["charts"]]
    assert "bin-picking.task.scxml" in names and "step01-bin-pick.scxml" in names
    task_chart = next(c for c in result["charts"] if c["kind"] == "task")
    scxml = await client.get(task_chart["scxml"])
    assert scxml.content.startswith(b"<?xml") and b"http://www.w3.org/2005/07/scxml" in scxml.content
    svg = await client.get(task_chart["svg"])
    assert svg.headers["content-type"] == "image/svg+xml"


async def test_a_task_chart_lists_its_steps_and_draws_one_expanded(client: httpx.AsyncClient) -> None:
    result = (await client.post("/api/task/generate", json=TASK)).json()
    task_chart = next(c for c in result["charts"] if c["kind"] == "task")
    steps = (await client.get(task_chart["scxml"] + "/steps")).json()
    assert [(s["number"], s["command"]) for s in steps] == [(n, ("bin-pick", "place")[(n - 1) % 2]) for n in range(1, 7)]
    assert steps[1]["binding"] == {"gripper": "gripper", "robot": "robot"} and steps[1]["chart"] == "step02-place.scxml"
    svg = (await client.get(task_chart["svg"] + "?step=2")).text
    assert "cluster_pnp_step_2" in svg and "cluster_pnp_step_1" not in svg
    assert (await client.get(task_chart["svg"] + "?step=0")).status_code == 422


async def test_generating_an_implausible_task_is_a_result(client: httpx.AsyncClient) -> None:
    result = (await client.post("/api/task/generate", json=INVALID)).json()
    assert result["plausible"] is False and result["charts"] == [] and result["problems"][0]["step"] == 2


def test_the_reasoner_check_matches_the_service() -> None:
    """The API converts the JSON task to the same model task the YAML file gives (one round per repeat)."""
    from plugnproduce.hmi.schemas import TaskIn

    from_file = service.task(service.builtin("tasks", "bin-picking.yaml"))
    # The JSON the editor sends for that file, written out here (not copied from the file's model).
    bind = {"sensor": "sensor3d", "localizer": "binpicking-pc", "robot": "robot", "gripper": "gripper"}
    from_json = TaskIn.model_validate({**TASK, "steps": [
        {**BIN_PICK, "bind": bind, "params": {"grip_force": 45, "exposure": 25, "part_type": "bracket"}},
        {**PLACE, "params": {"place_pose": [0.60, -0.20, 0.10, 0, 180, 0], "speed": 80}}]}).to_task()
    assert len(from_json.steps) == 6  # one round per repeat
    assert [(s.index, s.command, s.bind, s.params) for s in from_json.steps] == \
        [(s.index, s.command, s.bind, s.params) for s in from_file.steps]


@pytest.mark.parametrize("path", ["/api/task/validate", "/api/task/check", "/api/task/repair", "/api/task/generate"])
@pytest.mark.parametrize("value", [b"NaN", b"Infinity", b"-Infinity", b"[0.6, 0, NaN, 0, 0, 0]"])
async def test_a_parameter_that_is_not_a_finite_number_is_refused_not_a_crash(
        client: httpx.AsyncClient, path: str, value: bytes) -> None:
    body = b'{"name": "t", "steps": [{"command": "pick", "params": {"grip_force": ' + value + b"}}]}"
    res = await client.post(path, content=body, headers={"content-type": "application/json"})
    assert res.status_code == 422
    assert "is not a number a device can be given" in res.json()["detail"]


async def test_a_task_too_long_once_repeated_is_refused(client: httpx.AsyncClient) -> None:
    body = {"name": "t", "repeat": 1000, "steps": [{"command": "pick"}] * 1000}
    res = await client.post("/api/task/check", json=body)
    assert res.status_code == 422
    assert "1000 steps repeated 1000 times make 1000000; at most 10000 are accepted" in res.json()["detail"]


async def test_discover_json_shows_each_device_with_the_keys_and_values_of_the_http_api(
        client: httpx.AsyncClient, hmi: Hmi) -> None:
    """One device view: ``pnp discover --json`` on the HMI's simulated cell and ``GET /api/cell`` agree."""
    over_http = {d["id"]: d for d in (await client.get("/api/cell")).json()["devices"]}
    env = {**os.environ, "PNP_SSDP_PORT": str(hmi.source.network.port)}
    expect = ["--expect", str(len(over_http))]  # ends once they answered, not at a window
    command = [sys.executable, "-m", "plugnproduce", "discover", "--json", "--timeout", str(WAIT), *expect]
    done = await asyncio.to_thread(subprocess.run, command, env=env, capture_output=True, text=True,
                                   timeout=2 * WAIT)
    assert done.returncode == 0, done.stderr
    discovered = json.loads(done.stdout)["devices"]
    assert sorted(d["id"] for d in discovered) == sorted(over_http)
    for device in discovered:
        assert set(device) == {"id", "label", "classes", "skills", "protocol", "endpoint"}
        assert device == {key: over_http[device["id"]][key] for key in device}, device["id"]


async def test_the_editor_task_is_validated_imported_and_drawn_without_temporary_files(
        client: httpx.AsyncClient, hmi: Hmi, monkeypatch: pytest.MonkeyPatch) -> None:
    import tempfile

    from plugnproduce.hmi import jobs
    from plugnproduce.hmi.schemas import TaskIn

    def refuse(*_: object, **__: object) -> str:
        raise AssertionError("a temporary file was made")

    monkeypatch.setattr(tempfile, "mkdtemp", refuse)
    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    task, cell = TaskIn.model_validate(TASK), hmi.app.state.hub.planning_cell  # the requests' jobs, in this process
    assert jobs.validate(task)["valid"] is True
    assert jobs.import_yaml(service.task_text(task.to_task()).encode(), "t.yaml")["repeat"] == 3
    assert [c.kind for c in jobs.generate(task, cell)[1]].count("task") == 1
    assert (await client.post("/api/task/validate", json=TASK)).json()["valid"] is True
    text = (await client.post("/api/task/export", json=TASK)).text
    assert (await client.post("/api/task/import", content=text.encode(), headers=YAML)).json()["repeat"] == 3
    chart = next(c for c in (await client.post("/api/task/generate", json=TASK)).json()["charts"] if c["kind"] == "task")
    svg = await client.get(chart["svg"])
    assert svg.status_code == 200 and svg.content.lstrip().startswith((b"<?xml", b"<svg"))


def test_a_large_task_is_validated_in_one_pass_and_one_too_long_is_refused_before_any_work(
        served: Served, monkeypatch: pytest.MonkeyPatch) -> None:
    # issue 15: validating a fuzzed 100-step task in the editor took ~20 s (one SHACL query per value)
    from plugnproduce.hmi import jobs
    from plugnproduce.hmi.schemas import TaskIn
    from plugnproduce.validation import validate as validation

    passes: list[int] = []
    real = validation.shape_problems

    def counted(kg: object) -> object:
        passes.append(1)
        return real(kg)  # type: ignore[arg-type]

    step = {"command": "place", "params": {"place_pose": [0.6, -0.2, 0.1, 0, 180, 0], "speed": 9999}}
    with httpx.Client(base_url=served.url, timeout=600) as client:
        too_long = client.post("/api/task/validate", json={"name": "t", "steps": [step] * 1001})
        assert too_long.status_code == 422
        assert too_long.json()["detail"].startswith("steps: ") and "1000" in too_long.json()["detail"]
        largest = client.post("/api/task/validate", json={"name": "t", "steps": [step] * 1000})
        assert largest.status_code == 200
        problems = largest.json()["problems"]
        assert [p["row"] for p in problems] == list(range(1000))
        assert problems[999]["text"] == ("steps[999].params.speed: step 1000: parameter 'speed' is 9999 %; "
                                         "expected a value from 1 to 100 %")
        assert client.get("/api/cell").status_code == 200
    monkeypatch.setattr(validation, "shape_problems", counted)  # the request's job, here in this process
    assert jobs.validate(TaskIn.model_validate({"name": "t", "steps": [step] * 100}))["problems"] == problems[:100]
    assert passes == [1]
