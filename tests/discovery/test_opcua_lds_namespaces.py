"""Discovery through a Local Discovery Server across a real (virtual) network: the mixed cell's devices in one
network namespace, the controller in another, a veth link between them.

The LDS runs beside the devices (``pnp sim up --serve-lds``, the two-machine example of docs/opcua.md as it is
written there) or in the controller (``pnp discover --watch --serve-lds``). Security mode None off loopback is
refused unless ``PNP_OPCUA_ALLOW_INSECURE=1``; with a PKI folder the devices are spoken to with SignAndEncrypt.
Each test makes its own namespaces (:mod:`tests.namespaces`) and uses only their addresses.
"""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path
from typing import Any

from plugnproduce import service
from plugnproduce.protocols.upnp import private_network
from tests.discovery.test_network_namespaces import environment, host_of, pnp, simulated
from tests.lines import Lines
from tests.namespaces import linked_hosts
from tests.processes import started, stop

CELL = str(service.builtin("cells", "mixed.yaml"))
TASK = str(service.builtin("tasks", "pick-and-screw.yaml"))
MIXED = ["binpicking-pc-ua", "gripper", "robot", "screwdriver-ua", "sensor3d"]
OPCUA = ["binpicking-pc-ua", "screwdriver-ua"]
PORT = "4840"
"""The LDS's standard port: each namespace is a network of its own, so it is free there."""


def _journal_devices(ran: subprocess.CompletedProcess[str]) -> dict[str, str]:
    assert ran.returncode == 0, ran.stdout + ran.stderr
    report = json.loads(ran.stdout)
    assert report["outcome"] == "succeeded", report
    records = [json.loads(line) for line in Path(report["journal"]).read_text().splitlines()]
    devices: dict[str, str] = next(r["devices"] for r in records if "devices" in r)
    return devices


def test_the_docs_two_machine_example_with_the_lds_beside_the_devices(tmp_path: Path) -> None:
    """``pnp sim up CELL --serve-lds 4840`` on the devices' host (on its link's address); ``pnp discover --lds``
    and ``PNP_LDS=… pnp run --cell`` on the controller's. Only the LDS tells the first discover of the devices
    (its SSDP is on another port): refused in mode None off loopback, found once allowed."""
    with linked_hosts() as (devices, controller), \
            simulated(devices, CELL, tmp_path, "--interface", devices.interface, "--serve-lds", PORT) as log:
        lds = f"opc.tcp://{devices.address}:{PORT}"
        assert re.search(rf"^lds +opcua {re.escape(lds)}$", log.read_text(), re.M), log.read_text()
        lds_only = environment(tmp_path, PNP_SSDP_PORT=str(private_network().port))
        ask = ("discover", "--json", "--lds", lds, "--interface", controller.interface, "--timeout", "3600")

        refused = pnp(controller, *ask, "--settle", "1", env=lds_only)
        assert refused.returncode == 0, refused.stderr
        listed = json.loads(refused.stdout)
        assert listed["devices"] == []
        reasons = {r["udn"]: r["reason"] for r in listed["refused"]}
        assert sorted(reasons) == [f"urn:plugnproduce:device:{d}" for d in OPCUA], listed
        for device in OPCUA:
            assert re.fullmatch(
                rf"device {device}: opc\.tcp://{re.escape(devices.address)}:\d+/pnp/{device} is not on loopback and "
                r"security mode None would send in the clear; set PNP_OPCUA_PKI \(Sign or SignAndEncrypt\), or "
                r"allow it with PNP_OPCUA_ALLOW_INSECURE=1", reasons[f"urn:plugnproduce:device:{device}"])

        allowed = {"PNP_OPCUA_ALLOW_INSECURE": "1"}
        found = pnp(controller, *ask, "--expect", "2", env={**lds_only, **allowed})
        assert found.returncode == 0, found.stdout + found.stderr
        endpoints = {d["id"]: d["endpoint"] for d in json.loads(found.stdout)["devices"]}
        assert sorted(endpoints) == OPCUA
        for device in OPCUA:
            assert re.search(rf"^{device} +opcua {re.escape(endpoints[device])}$", log.read_text(), re.M)
            assert host_of(endpoints[device]) == devices.address

        ran = pnp(controller, "run", TASK, "--cell", CELL, "--json", "--interface", controller.interface,
                  env=environment(tmp_path, PNP_LDS=lds, **allowed))
        spoken_to = _journal_devices(ran)
        assert sorted(spoken_to) == MIXED
        assert {host_of(endpoint) for endpoint in spoken_to.values()} == {devices.address}


def _changes(lines: Lines, kind: str, wanted: list[str]) -> list[dict[str, Any]]:
    """The watch's lines up to the ``kind`` changes of every device of ``wanted`` (others, e.g. refusals of
    the moment, skipped: they fail the test only through what is missing)."""
    seen: list[dict[str, Any]] = []
    while sorted(c["device"] for c in seen if c.get("change") == kind) != wanted:
        seen.append(json.loads(lines.next()))
    return seen


def test_the_controllers_lds_across_the_link_with_signandencrypt(tmp_path: Path) -> None:
    """``pnp discover --watch --serve-lds 4840`` on the controller's host; ``pnp sim up --lds`` on the devices'
    registers there across the link; the OPC UA devices are plugged (read with SignAndEncrypt, no insecure
    opt-in), the mixed task runs with ``PNP_LDS`` naming the controller's LDS, and the devices are unplugged
    when they stop."""
    secure = {"PNP_OPCUA_PKI": str(tmp_path / "pki"), "PNP_OPCUA_SECURITY": "SignAndEncrypt"}
    with linked_hosts() as (devices, controller):
        lds_only = environment(tmp_path, PNP_SSDP_PORT=str(private_network().port), **secure)
        watch_args = ("discover", "--watch", "--json", "--serve-lds", PORT, "--interface", controller.interface,
                      "--timeout", "1", "--settle", "0.2")
        with started(controller.pnp(*watch_args), env=lds_only, text=True, stdout=subprocess.PIPE) as watch:
            lines = Lines(watch.stdout)
            first = json.loads(lines.next())
            lds = f"opc.tcp://{controller.address}:{PORT}"
            assert (first["lds"], first["devices"]) == (lds, []), first
            with simulated(devices, CELL, tmp_path, "--interface", devices.interface, "--lds", lds, **secure):
                plugged = _changes(lines, "plug", OPCUA)
                assert not [c for c in plugged if c["change"] == "refused"], plugged
                assert plugged[-1]["devices"] == OPCUA

                ran = pnp(controller, "run", TASK, "--cell", CELL, "--json", "--interface", controller.interface,
                          env=environment(tmp_path, PNP_LDS=lds, **secure))
                spoken_to = _journal_devices(ran)
                assert sorted(spoken_to) == MIXED
                assert {host_of(endpoint) for endpoint in spoken_to.values()} == {devices.address}
            unplugged = _changes(lines, "unplug", OPCUA)
            assert unplugged[-1]["devices"] == []
            stop(watch)
            lines.rest()
            assert watch.stdout is not None
            watch.stdout.close()
