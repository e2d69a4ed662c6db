"""The live cell follows devices that announce themselves over SSDP on loopback."""

from __future__ import annotations

import asyncio
import logging
import socket
import threading
from collections.abc import Mapping
from typing import Any

import pytest

from plugnproduce.discovery import LiveCell
from plugnproduce.discovery.live import CONFIRM_TIMEOUT
from plugnproduce.protocols.upnp import (
    SERVICE_TYPE,
    DeviceFiles,
    SsdpNetwork,
    UpnpDeviceServer,
    device_type_for,
    discover,
    service_spec_from_chart_events,
    udn_for,
)
from plugnproduce.resources import descriptions_path
from tests.lines import WAIT


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


async def answer(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
    return {"Result": "accepted"}


def sensor_server(network: SsdpNetwork, device_id: str = "sensor3d") -> UpnpDeviceServer:
    folder = descriptions_path() / "devices"
    files = DeviceFiles("sensor3d.ttl", (folder / "sensor3d.ttl").read_text(), "sensor3d.scxml",
                        (folder / "sensor3d.scxml").read_text())
    spec = service_spec_from_chart_events({"Capture": ["Exposure"]}, ["CaptureDone"])
    return UpnpDeviceServer(device_id, "3D sensor", device_type_for("StereoCamera"), spec, answer, files=files,
                            network=network)


@pytest.fixture
def network() -> SsdpNetwork:
    return SsdpNetwork(port=free_udp_port())


async def test_device_present_at_start_is_in_the_cell(network, taxonomy) -> None:
    async with sensor_server(network), LiveCell(taxonomy, network=network) as live:
        change = await live.next_change(WAIT)
        assert (change.kind, change.device) == ("plug", "sensor3d")
        device = live.cell.device("sensor3d")
        assert "http://plugnproduce.org/ontology#CanSense3D" in device.skills
        assert {s.id for s in device.states} == {"ready", "capturing", "captured"}


async def test_plug_and_unplug_are_followed(network, taxonomy) -> None:
    async with LiveCell(taxonomy, network=network) as live:
        assert live.cell.devices == ()
        server = sensor_server(network)
        await server.start()
        plugged = await live.next_change(WAIT)
        assert (plugged.kind, plugged.device) == ("plug", "sensor3d")
        await server.stop()
        unplugged = await live.next_change(WAIT)
        assert (unplugged.kind, unplugged.device) == ("unplug", "sensor3d")
        assert unplugged.cell.devices == ()


# --- one bad device costs only itself ------------------------------------------------------


def bad_sensor(network: SsdpNetwork, turtle_edit: tuple[str, str], device_id: str = "evil") -> UpnpDeviceServer:
    folder = descriptions_path() / "devices"
    turtle = (folder / "sensor3d.ttl").read_text().replace("dev:sensor3d", f"dev:{device_id}")
    assert turtle_edit[0] in turtle
    files = DeviceFiles("sensor3d.ttl", turtle.replace(*turtle_edit), "sensor3d.scxml",
                        (folder / "sensor3d.scxml").read_text())
    spec = service_spec_from_chart_events({"Capture": ["Exposure"]}, ["CaptureDone"])
    return UpnpDeviceServer(device_id, "3D sensor", device_type_for("StereoCamera"), spec, answer, files=files,
                            network=network)


async def changes_until(live: LiveCell, kind: str, device: str) -> list[tuple[str, str]]:
    seen = []
    while (kind, device) not in seen:
        change = await live.next_change(WAIT)
        seen.append((change.kind, change.device))
    return seen


@pytest.mark.parametrize("edit", [
    ("pnp:stateChart <sensor3d.scxml>", "pnp:stateChart <file:///etc/passwd>"),
    ("pnp:stateChart <sensor3d.scxml>", f"pnp:stateChart <{(descriptions_path() / 'devices' / 'sensor3d.scxml').as_uri()}>"),
    ("pnp:stateChart <sensor3d.scxml>", "pnp:stateChart <http://192.0.2.1/sensor3d.scxml>"),
    ("pnp:protocol", 'pnp:cost "abc"^^<http://www.w3.org/2001/XMLSchema#decimal> ;\n    pnp:protocol'),
    ("pnp:protocol pnp:UPnP", "pnp:protocol pnp:UPnP ; ; ; ."),
], ids=["system file chart", "local chart", "chart on another host", "bad literal", "malformed"])
async def test_a_bad_device_is_refused_and_the_others_are_still_followed(network, taxonomy, edit) -> None:
    async with LiveCell(taxonomy, network=network) as live:
        async with bad_sensor(network, edit):
            refused = await live.next_change(WAIT)
            assert refused.kind == "refused" and "\n" not in refused.reason
            assert "root:" not in refused.reason  # nothing of a local file is read, let alone quoted
            assert "pnp-live-" not in refused.reason and "/served/" not in refused.reason  # nor a folder of the controller
        honest = sensor_server(network)
        await honest.start()
        assert ("plug", "sensor3d") in await changes_until(live, "plug", "sensor3d")
        await honest.stop()
        assert ("unplug", "sensor3d") in await changes_until(live, "unplug", "sensor3d")
        assert live.cell.devices == ()


async def test_a_spoofed_byebye_does_not_unplug_a_device_that_still_answers(network, taxonomy) -> None:
    async with sensor_server(network), LiveCell(taxonomy, network=network) as live:
        assert (await live.next_change(WAIT)).kind == "plug"
        impostor = sensor_server(network)  # same predictable UDN, another address
        await impostor.start()
        await impostor.stop()  # its byebye names the real device's UDN
        with pytest.raises(TimeoutError):
            await live.next_change(2 * CONFIRM_TIMEOUT + 0.5)
        assert [d.id for d in live.cell.devices] == ["sensor3d"]
async def test_entering_returns_once_the_expected_devices_have_answered(network, taxonomy) -> None:
    # A search window far longer than the suite's limit: entering must not wait for the window to end.
    async with sensor_server(network), asyncio.timeout(WAIT):
        async with LiveCell(taxonomy, network=network, search_timeout=3600, expected=["sensor3d"]) as live:
            assert [d.id for d in live.cell.devices] == ["sensor3d"]


async def test_an_expected_device_that_never_answers_costs_the_window_only(network, taxonomy) -> None:
    # The gripper never answers: entering ends with the window (1 s), far within the suite's limit. The sensor
    # plugs in, from the search if it answered within the window, else from its next announcement.
    async with sensor_server(network), asyncio.timeout(WAIT):
        async with LiveCell(taxonomy, network=network, search_timeout=1, expected=["gripper", "sensor3d"]) as live:
            assert ("plug", "sensor3d") in await changes_until(live, "plug", "sensor3d")
            assert [d.id for d in live.cell.devices] == ["sensor3d"]


async def test_a_device_is_read_from_the_files_it_serves_without_writing_them(network, taxonomy,
                                                                             monkeypatch) -> None:
    import tempfile

    def refuse(*_: object, **__: object) -> str:
        raise AssertionError("discovery wrote a device's files to disk")

    monkeypatch.setattr(tempfile, "mkdtemp", refuse)
    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    async with sensor_server(network), LiveCell(taxonomy, network=network) as live:
        assert await changes_until(live, "plug", "sensor3d") == [("plug", "sensor3d")]
        device = live.cell.device("sensor3d")
        assert {s.id for s in device.states} == {"ready", "capturing", "captured"}
        assert device.chart.states() and device.initial == "ready"


# --- an impostor announcing a device's UDN does not keep the device out ------------------


def squatter_alive(network: SsdpNetwork, udn: str, location: str, extra: str = "", encoding: str = "utf-8") -> None:
    """One SSDP alive for ``udn`` pointing at ``location``, sent from a plain UDP socket."""
    message = (f"NOTIFY * HTTP/1.1\r\nHOST: {network.group}:{network.port}\r\nCACHE-CONTROL: max-age=1800\r\n"
               f"LOCATION: {location}\r\nNT: upnp:rootdevice\r\nNTS: ssdp:alive\r\nSERVER: squatter/1 UPnP/1.0 x/1\r\n"
               f"USN: {udn}::upnp:rootdevice\r\n{extra}\r\n").encode(encoding)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sock.sendto(message, (network.group, network.port))


async def test_an_alive_squatting_a_device_s_udn_does_not_keep_the_device_out(network, taxonomy) -> None:
    udn = udn_for("sensor3d")
    async with LiveCell(taxonomy, network=network) as live:
        squatter_alive(network, udn, f"http://127.0.0.1:{free_udp_port()}/description.xml")  # nobody answers there
        refused = await live.next_change(WAIT)
        assert (refused.kind, refused.device) == ("refused", udn)
        async with sensor_server(network):
            assert ("plug", "sensor3d") in await changes_until(live, "plug", "sensor3d")
            assert [d.id for d in live.cell.devices] == ["sensor3d"]


async def test_an_impostor_serving_a_bad_description_under_the_udn_is_refused_and_the_device_plugged(
        network, taxonomy) -> None:
    impostor = bad_sensor(network, ("pnp:protocol pnp:UPnP", "pnp:protocol pnp:UPnP ; ; ; ."), device_id="sensor3d")
    async with LiveCell(taxonomy, network=network) as live:
        async with impostor:  # announced first
            assert await changes_until(live, "refused", udn_for("sensor3d")) == [("refused", udn_for("sensor3d"))]
            async with sensor_server(network):
                assert ("plug", "sensor3d") in await changes_until(live, "plug", "sensor3d")
                assert [d.id for d in live.cell.devices] == ["sensor3d"]



async def test_a_datagram_with_a_duplicate_or_undecodable_header_is_dropped_without_a_traceback(network, taxonomy, caplog) -> None:
    # async-upnp-client let aiohttp's BadHttpMessage out of its protocol: asyncio logged a traceback per datagram
    async with LiveCell(taxonomy, network=network) as live:
        for _ in range(3):
            squatter_alive(network, "uuid:dup", "http://127.0.0.1:1/d.xml", extra=f"HOST: {network.group}\r\n")
            squatter_alive(network, "uuid:latin", "http://127.0.0.1:1/d.xml", extra="SERVER: Gr\xfc\xdfe\r\n",
                           encoding="latin-1")  # a header that is not UTF-8
        async with sensor_server(network):
            assert await changes_until(live, "plug", "sensor3d") == [("plug", "sensor3d")]
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR] == []


class SearchSquatter:
    """Answers every M-SEARCH on ``network`` as ``udn``, pointing at a description nobody serves."""

    def __init__(self, network: SsdpNetwork, udn: str) -> None:
        self.udn = udn
        self.location = f"http://127.0.0.1:{free_udp_port()}/description.xml"
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        self.sock.bind(("", network.port))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                             socket.inet_aton(network.group) + socket.inet_aton(network.interface))
        self.sock.settimeout(0.2)
        self.answered = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                data, addr = self.sock.recvfrom(4096)
            except TimeoutError:
                continue
            if data.startswith(b"M-SEARCH"):
                self.sock.sendto((f"HTTP/1.1 200 OK\r\nCACHE-CONTROL: max-age=1800\r\nEXT:\r\n"
                                  f"LOCATION: {self.location}\r\nSERVER: squatter/1 UPnP/1.0 x/1\r\n"
                                  f"ST: {SERVICE_TYPE}\r\nUSN: {self.udn}::{SERVICE_TYPE}\r\n\r\n").encode(), addr)
                self.answered += 1

    def __enter__(self) -> SearchSquatter:
        self._thread.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._stop.set()
        self._thread.join(5)
        self.sock.close()


async def test_discover_takes_the_place_of_a_udn_whose_description_reads_not_the_first_answer(network) -> None:
    async with sensor_server(network) as honest:
        with SearchSquatter(network, udn_for("sensor3d")) as squatter:  # answers at once; the device after a delay
            found = await discover(2.0, network=network)
    assert squatter.answered >= 1
    assert [(d.udn, d.location) for d in found.devices] == [(udn_for("sensor3d"), honest.location)]
    assert [(r.udn, r.location) for r in found.refused] == [(udn_for("sensor3d"), squatter.location)]


async def test_issue_15_discover_waits_for_an_expected_device_whose_description_reads_not_its_squatter(
        network) -> None:
    # the search ended once each expected UDN had answered once: a squatter answering first ended it,
    # and the real device, answering a moment later, was never read
    async with sensor_server(network) as honest:
        with SearchSquatter(network, udn_for("sensor3d")) as squatter:  # answers at once; the device within MX s
            found = await discover(30.0, network=network, expected=[udn_for("sensor3d")])
    assert squatter.answered >= 1
    assert [(d.udn, d.location) for d in found.devices] == [(udn_for("sensor3d"), honest.location)]
    assert (udn_for("sensor3d"), squatter.location) in [(r.udn, r.location) for r in found.refused]
