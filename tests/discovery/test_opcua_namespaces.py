"""OPC UA on a real (virtual) network: the mixed cell's devices in one network namespace, the controller in another.

The OPC UA devices' servers listen on the chosen interface's address (not loopback), and the controller reaches
them there across a veth link, beside the XIRP and UPnP devices of the same cell. Each test makes its own
namespaces (:mod:`tests.namespaces`) and uses only their addresses.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from plugnproduce import service
from tests.discovery.test_network_namespaces import environment, host_of, pnp, simulated
from tests.namespaces import linked_hosts

CELL = str(service.builtin("cells", "mixed.yaml"))
TASK = str(service.builtin("tasks", "pick-and-screw.yaml"))
MIXED = ["binpicking-pc-ua", "gripper", "robot", "screwdriver-ua", "sensor3d"]
OPCUA = ["binpicking-pc-ua", "screwdriver-ua"]


def test_the_mixed_task_runs_on_opc_ua_devices_in_another_namespace(tmp_path: Path) -> None:
    """``pnp sim up --interface`` binds the OPC UA servers to the link's address; ``pnp run --cell`` on the other
    host finds them there and runs pick-and-screw over OPC UA, XIRP and UPnP across the link."""
    with linked_hosts() as (devices, controller), \
            simulated(devices, CELL, tmp_path, "--interface", devices.interface) as log:
        printed = log.read_text()
        for device in OPCUA:
            assert re.search(rf"^{device} +opcua opc\.tcp://{re.escape(devices.address)}:\d+/pnp/{device}$",
                             printed, re.M), printed
        env = environment(tmp_path)
        found = pnp(controller, "discover", "--json", "--cell", CELL, "--timeout", "3600",
                    "--interface", controller.interface, env=env)
        assert found.returncode == 0, found.stderr
        listed = {d["id"]: d for d in json.loads(found.stdout)["devices"]}
        assert sorted(listed) == MIXED
        assert {host_of(d["endpoint"]) for d in listed.values()} == {devices.address}
        assert sorted(i for i, d in listed.items() if d["protocol"] == "opcua") == OPCUA

        # security mode None off loopback is refused unless allowed: this link is the test's own, made for it
        ran = pnp(controller, "run", TASK, "--cell", CELL, "--json", "--interface", controller.interface,
                  env={**env, "PNP_OPCUA_ALLOW_INSECURE": "1"})
        assert ran.returncode == 0, ran.stdout + ran.stderr
        report = json.loads(ran.stdout)
        assert report["outcome"] == "succeeded", report
        records = [json.loads(line) for line in Path(report["journal"]).read_text().splitlines()]
        spoken_to = next(r["devices"] for r in records if "devices" in r)
        assert sorted(spoken_to) == MIXED
        assert {host_of(spoken_to[d]) for d in OPCUA} == {devices.address}
        assert all(spoken_to[d].startswith("opc.tcp://") for d in OPCUA)
        screwing = [r["event"] for r in records if r.get("kind") == "event" and r.get("device") == "screwdriver-ua"]
        assert screwing == ["Completed", "Completed"]
