"""Library devices in the simulated cell: plugged in by description file, and listed by the HMI."""

from __future__ import annotations

import httpx

from plugnproduce import service
from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app
from plugnproduce.protocols import upnp
from plugnproduce.sim.cell import SimulatedCell
from tests.knowledge.test_libraries import THREE_FINGER

GRIPPER_3F = THREE_FINGER / "devices" / "gripper-3f.ttl"


async def test_issue_11_sim_plug_takes_a_device_description_file() -> None:
    k = service.knowledge((THREE_FINGER,))
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    async with SimulatedCell(cell, network=upnp.private_network(), taxonomy=k.taxonomy) as sim:
        running = await sim.control("plug", str(GRIPPER_3F))
        assert "gripper-3f" in running
        assert sim.catalogue["gripper-3f"].classes == ("http://example.org/three-finger#ThreeFingerGripper",)


async def test_issue_11_the_hmi_plug_list_shows_library_devices(tmp_path) -> None:
    k = service.knowledge((THREE_FINGER,))
    source = SimulatedCellSource(service.cell(service.builtin("cells", "bin-picking.yaml"), k),
                                 service.catalogue(knowledge=k), knowledge=k)
    app = create_app(source, ExecutorRunner(source, tmp_path / "runs", k), "t" * 24, knowledge=k)
    transport = httpx.ASGITransport(app=app, client=("127.0.0.1", 50000))
    async with app.router.lifespan_context(app):
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as client:
            listed = (await client.get("/api/catalogue")).json()
            processes = (await client.get("/api/processes")).json()
            task = {"task": "s", "steps": [{"command": "squeeze", "bind": {}, "params": {}}]}
            validated = (await client.post("/api/task/validate", json=task)).json()
    assert "gripper-3f" in [d["id"] for d in listed]
    assert "squeeze" in [p["command"] for p in processes]
    assert validated["valid"], validated
