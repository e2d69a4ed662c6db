"""The step dialog's Teach (``/api/teach``) over every protocol: the short-arm library's arm over XIRP, UPnP and
OPC UA, simulated and found by discovery, as the page asks for it."""

from __future__ import annotations

from pathlib import Path

import httpx

from plugnproduce import service
from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app
from tests.hmi.conftest import TOKEN

SHORT_ARM = Path(__file__).parents[1] / "data" / "libraries" / "short-arm"
ARMS = ("short-arm", "short-arm-upnp", "short-arm-ua")


async def test_teach_reads_the_pose_of_the_arm_over_each_protocol_and_says_why_it_is_refused(tmp_path: Path) -> None:
    k = service.knowledge((SHORT_ARM,))
    cell = service.cell(SHORT_ARM / "cells" / "short-arms.yaml", k)
    source = SimulatedCellSource(cell, service.catalogue(knowledge=k), knowledge=k)
    app = create_app(source, ExecutorRunner(source, tmp_path / "runs"), TOKEN, knowledge=k)
    transport = httpx.ASGITransport(app=app, client=("127.0.0.1", 50000))
    async with app.router.lifespan_context(app):
        async with httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1") as c:
            reports = (await c.get("/api/teach")).json()
            answers = [(await c.get(f"/api/teach/{arm}/TargetPose")).json() for arm in ARMS]
    assert reports == {"reports": {arm: ["TargetPose"] for arm in ARMS}}
    for arm, answer in zip(ARMS, answers, strict=True):
        assert answer == {"device": arm, "quantity": "TargetPose", "value": [0.4, 0.0, 0.6, 0.0, 180.0, 0.0],
                          "unit": "", "state": "home", "accepted": False,
                          "held_to": ["MoveTo TargetPose: Pose, reach 0.5 m"],
                          "refused": [f"{arm} MoveTo TargetPose reaches at most 0.5 m from its base; the pose is "
                                      "0.721 m away"]}
