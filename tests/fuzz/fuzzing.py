"""The fuzz campaign's targets and mutators, shared by the Hypothesis tests and ``scripts/fuzz.py``.

A *target* reads one input through the project's real entry point (the loaders, the
validator, the XIRP decoder, the live cell's reading of what a device served, a device's
UPnP root description and SCPD, an SSDP datagram as discovery receives it) and
returns ``"accepted"`` or ``"refused"``. A refusal must be the documented one (a
:class:`~plugnproduce.errors.DescriptionError`, a :class:`~plugnproduce.errors.ProtocolError`
such as XIRP's ``MessageError``, or a problem in a validation report) with a message
that is one line, no traceback, and quotes at most a short excerpt of the input; any
other outcome raises :class:`Crash`.

Mutators start from the built-in examples and damage them: byte flips, truncation,
duplication, numbers replaced by huge/NaN/negative values, injected tags, attributes
and prefixes, deep nesting.
"""

from __future__ import annotations

import functools
import random
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from plugnproduce.errors import DescriptionError, ProtocolError, excerpt
from plugnproduce.resources import descriptions_path

MAX_MESSAGE = 1000
"""Longest error message accepted from a refusal (a short excerpt of the input at most)."""

MAX_QUOTE = 120
"""Longest run of the input a message may quote."""


class Crash(Exception):
    """A case that ended otherwise than documented: an unexpected exception type or a bad message."""


def check_message(message: str, data: bytes | str) -> None:
    """Raise :class:`Crash` unless ``message`` is one short line quoting no more than a short excerpt of ``data``."""
    if "\n" in message or "\r" in message:
        raise Crash(f"message of more than one line: {message[:300]!r}")
    if "Traceback" in message:
        raise Crash(f"traceback in message: {message[:300]!r}")
    if len(message) > MAX_MESSAGE:
        raise Crash(f"message of {len(message)} characters: {message[:300]!r}")
    text = data.decode("utf-8", "replace") if isinstance(data, bytes) else data
    half = MAX_QUOTE // 2
    for start in range(0, max(len(text) - half, 0) + 1, half):
        window = text[start:start + half]  # any quote of MAX_QUOTE characters contains one aligned window
        if len(window) < half or len(set(window)) < 8:  # "((((" quotes nothing
            continue
        at = message.find(window)
        while at >= 0:
            if _quoted_length(message, at, text, start, half) >= MAX_QUOTE:
                raise Crash(f"message quotes the input at length: {message[:300]!r}")
            at = message.find(window, at + 1)


def _quoted_length(message: str, at: int, text: str, start: int, n: int) -> int:
    """How long the run of ``text`` quoted at ``message[at:]`` is, ``n`` characters known to match."""
    left = 0
    while at - left > 0 and start - left > 0 and message[at - left - 1] == text[start - left - 1]:
        left += 1
    right = 0
    while (at + n + right < len(message) and start + n + right < len(text)
           and message[at + n + right] == text[start + n + right]):
        right += 1
    return left + n + right


# ---------------------------------------------------------------------------------------------------------------
# Seeds and mutators

DESCRIPTIONS = descriptions_path()


def seeds(kind: str) -> list[tuple[str, bytes]]:
    """The built-in examples of a kind as ``(relative path, bytes)``: devices, processes, charts, tasks, cells."""
    patterns = {
        "turtle": ["devices/*.ttl", "processes/*.ttl"],
        "chart": ["devices/*.scxml", "processes/*.scxml"],
        "task": ["tasks/*.yaml"],
        "cell": ["cells/*.yaml"],
    }[kind]
    out = []
    for pattern in patterns:
        for f in sorted(DESCRIPTIONS.glob(pattern)):
            out.append((str(f.relative_to(DESCRIPTIONS)), f.read_bytes()))
    return out


NUMBERS = [b"0", b"-1", b"-0.0", b"1e308", b"1e309", b"-1e309", b"NaN", b"nan", b".nan", b"INF", b"-INF", b".inf",
           b"9" * 40, b"9" * 5000, b"1" + b"0" * 400, b"0x1F", b"1_000", b"2.5e-400", b"\"NaN\"^^xsd:double",
           b"\"abc\"^^xsd:decimal", b"\"1e999\"^^xsd:double", b"\"-5\"^^xsd:nonNegativeInteger",
           b"\"x\"^^xsd:boolean", b"\"2020-13-45\"^^xsd:date", b"10**10**10", b"'a'*10**9", b"-99999999999999999999"]
INJECTIONS = [
    b"<!DOCTYPE x [<!ENTITY e \"e\">]>", b"<!-- <!DOCTYPE x> -->", b"<x:y xmlns:x=\"urn:x\"/>", b"<state id=\"s\"/>",
    b"<transition target=\"nowhere\"/>", b"<script>import os</script>", b" foo=\"bar\"", b" id=\"dup\"",
    b" cond=\"10**10**10\"", b" expr=\"[1]*10**9\"", b"&amp;", b"&e;", b"&#0;", b"]]>", b"<![CDATA[x]]>",
    b"@prefix p: <urn:p> .\n", b"@base <file:///etc/> .\n", b"<file:///etc/passwd>", b"<http://10.0.0.1/x.scxml>",
    b"\"\"\"", b"^^", b" ; ", b" , ", b" . ", b"_:b", b"[ ", b" ]", b"( ", b")",
    b"!!timestamp 2020-13-45", b"!!omap [a: 1]", b"!!binary aGk=", b"!!python/object:os.system", b"&a x", b"*a",
    b"? ", b"- ", b": ", b"{", b"}", b"[", b"]", b"'", b"\"", b"\t", b"%YAML 1.1\n", b"---\n", b"...\n",
    b"\x00", b"\xff\xfe", b"\xef\xbb\xbf", b"\xc3\x28", b"\xed\xa0\x80", b"\r", "\u2028".encode(),
    b"repeat: 100000\n", b"repeat: -1\n", b"steps: []\n", b"steps: {}\n", b"devices: [/etc/passwd]\n",
    b"devices: [/dev/zero]\n", b"devices: [.]\n", b"command: x\n",
]


def _flip(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    i = rng.randrange(len(data))
    return data[:i] + bytes([data[i] ^ (1 << rng.randrange(8))]) + data[i + 1:]


def _truncate(data: bytes, rng: random.Random) -> bytes:
    return data[:rng.randrange(len(data) + 1)]


def _duplicate(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    i, j = sorted(rng.randrange(len(data) + 1) for _ in range(2))
    k = rng.randrange(len(data) + 1)
    return data[:k] + data[i:j] * rng.choice([1, 2, 5]) + data[k:]


def _delete(data: bytes, rng: random.Random) -> bytes:
    if not data:
        return data
    i = rng.randrange(len(data))
    return data[:i] + data[i + rng.randrange(1, 40):]


def _number(data: bytes, rng: random.Random) -> bytes:
    spans = [(i, j) for i, j in _digit_runs(data)]
    if not spans:
        return _insert(data, rng)
    i, j = rng.choice(spans)
    return data[:i] + rng.choice(NUMBERS) + data[j:]


def _digit_runs(data: bytes) -> list[tuple[int, int]]:
    runs, start = [], None
    for i, b in enumerate(data):
        digit = 48 <= b <= 57 or (start is not None and b == 46)
        if digit and start is None:
            start = i
        elif not digit and start is not None:
            runs.append((start, i))
            start = None
    if start is not None:
        runs.append((start, len(data)))
    return runs


def _insert(data: bytes, rng: random.Random) -> bytes:
    i = rng.randrange(len(data) + 1)
    return data[:i] + rng.choice(INJECTIONS) + data[i:]


def _nest(data: bytes, rng: random.Random) -> bytes:
    depth = rng.choice([10, 70, 200, 3000])
    opener, closer = rng.choice([(b"<state>", b"</state>"), (b"[", b"]"), (b"{a: ", b"}"), (b"- ", b""),
                                 (b"(", b")"), (b"[ <urn:p> ", b" ]")])
    i = rng.randrange(len(data) + 1)
    return data[:i] + opener * depth + closer * depth + data[i:]


def _swap_lines(data: bytes, rng: random.Random) -> bytes:
    lines = data.split(b"\n")
    if len(lines) < 2:
        return data
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[i], lines[j] = lines[j], lines[i]
    return b"\n".join(lines)


MUTATORS: list[Callable[[bytes, random.Random], bytes]] = [
    _flip, _truncate, _duplicate, _delete, _number, _number, _insert, _insert, _nest, _swap_lines,
]


def mutate(data: bytes, rng: random.Random) -> bytes:
    """``data`` damaged by one to four random mutations."""
    for _ in range(rng.choice([1, 1, 2, 3, 4])):
        data = rng.choice(MUTATORS)(data, rng)
    return data


# ---------------------------------------------------------------------------------------------------------------
# Targets


@dataclass
class Workspace:
    """A private copy of the built-in descriptions, so a case's file sits next to the files it names."""

    root: Path = field(default_factory=lambda: Path(tempfile.mkdtemp(prefix="fuzz-")))

    def __post_init__(self) -> None:
        shutil.copytree(DESCRIPTIONS, self.root / "descriptions", dirs_exist_ok=True)

    def write(self, relative: str, data: bytes) -> Path:
        """Write a case beside the file it mutates (``devices/case.ttl`` for ``devices/gripper.ttl``)."""
        original = self.root / "descriptions" / relative
        path = original.with_name("case" + original.suffix)
        path.write_bytes(data)
        return path

    def close(self) -> None:
        """Remove the copy."""
        shutil.rmtree(self.root, ignore_errors=True)


def _refused(exc: Exception, data: bytes) -> str:
    check_message(str(exc), data)
    return "refused"


def _report(report: object, data: bytes) -> str:
    for problem in report.sorted():  # type: ignore[attr-defined]
        check_message(str(problem), data)
    return "accepted" if report.valid else "refused"  # type: ignore[attr-defined]


def run_turtle(ws: Workspace, relative: str, data: bytes, deep: bool = True) -> str:
    """A device or process description: read it, then (``deep``) validate it as ``pnp validate`` does."""
    from plugnproduce import service
    from plugnproduce.description.loader import load_device, load_process

    path = ws.write(relative, data)
    try:
        if relative.startswith("devices/"):
            load_device(path, service.knowledge().taxonomy)
        else:
            load_process(path)
    except DescriptionError as exc:
        if not deep:
            return _refused(exc, data)
        _refused(exc, data)
    return _report(service.validate([path]), data) if deep else "accepted"


def run_chart(ws: Workspace, relative: str, data: bytes, deep: bool = True) -> str:
    """A chart: the runtime's reader, the description's view of it, and the schema and structure checks."""
    from plugnproduce.description.charts import device_chart, process_regions
    from plugnproduce.statechart.io.reader import parse_chart

    path = ws.write(relative, data)
    try:
        chart = parse_chart(data, path)
        device_chart(chart, path) if relative.startswith("devices/") else process_regions(chart, path)
    except DescriptionError as exc:
        if not deep:
            return _refused(exc, data)
        _refused(exc, data)
    from plugnproduce import service

    return _report(service.validate([path]), data) if deep else "accepted"


def run_task(ws: Workspace, relative: str, data: bytes, deep: bool = True) -> str:
    """A task file: read and checked against the built-in processes (no reasoning)."""
    from plugnproduce.description.loader import load_task

    path = ws.write(relative, data)
    try:
        load_task(path)
    except DescriptionError as exc:
        return _refused(exc, data)
    from plugnproduce import service

    return _report(service.validate([path]), data) if deep else "accepted"


def run_cell(ws: Workspace, relative: str, data: bytes, deep: bool = True) -> str:
    """A cell file: read with its devices, then validated."""
    from plugnproduce import service

    path = ws.write(relative, data)
    try:
        service.cell(path)
    except DescriptionError as exc:
        if not deep:
            return _refused(exc, data)
        _refused(exc, data)
    return _report(service.validate([path]), data) if deep else "accepted"


def run_xirp(data: bytes) -> str:
    """One XIRP frame's payload through the decoder; the only refusal is ``MessageError``."""
    from plugnproduce.protocols.xirp import MessageError, decode

    try:
        decode(data, "message from 127.0.0.1:9")
    except MessageError as exc:
        return _refused(exc, data)
    return "accepted"


def xirp_seeds() -> list[bytes]:
    """Encoded messages of every kind, as a device and the controller send them."""
    from plugnproduce.protocols.xirp import Bye, ErrorMessage, Event, Hello, Pose, Request, Response, encode

    messages = [
        Hello("gripper", "http://plugnproduce.org/ontology#ParallelGripper", "Parallel gripper PG-70"),
        Request("1", "Open"),
        Request("2", "MoveTo", {"Target": Pose(0.5, -0.2, 0.1, 0.0, 180.0, 0.0), "Speed": 80, "Fast": True,
                                "Part": "bracket", "Force": 45.5}),
        Response("1"),
        Response("2", {"Position": 0.25, "Count": 3}),
        Event("gripper_closed", 3, datetime(2024, 5, 1, 10, tzinfo=UTC), {"GripForce": 40.0}),
        ErrorMessage("malformed", "the frame is not XML", "7"),
        Bye(),
    ]
    out = []
    for m in messages:
        try:
            out.append(encode(m))
        except (TypeError, ValueError, ProtocolError):  # a seed whose signature changed: skip, the rest still fuzz
            continue
    return out


def run_served(ws: Workspace, device: str, description: bytes, chart: bytes, location: str) -> str:
    """What the live cell reads from a device it found: its Turtle and chart as served, then the endpoint rule."""
    from plugnproduce import service
    from plugnproduce.discovery.served import read_served
    from plugnproduce.protocols.upnp import FoundDevice, RemoteFiles

    base = location.rsplit("/", 1)[0]
    files = RemoteFiles(f"{base}/{device}.ttl", description.decode("utf-8", "replace"), f"{base}/{device}.scxml",
                        chart.decode("utf-8", "replace"))
    found = FoundDevice("uuid:fuzz", location, "urn:schemas-plugnproduce-org:device:Device:1", "fuzz", "127.0.0.1")
    try:
        read_served(files, found, service.knowledge().taxonomy)
    except (DescriptionError, ProtocolError) as exc:
        return _refused(exc, description + b"\n" + chart)
    return "accepted"


def run_reference(location: str, reference: str) -> str:
    """A URL a device's description names (``pnp:chartURL``): resolved only to the host it was found at."""
    from plugnproduce.protocols.upnp import UntrustedUrlError
    from plugnproduce.protocols.upnp.boundary import resolve_trusted

    try:
        resolve_trusted(location, reference, "127.0.0.1", "pnp:chartURL of uuid:fuzz")
    except UntrustedUrlError as exc:
        return _refused(exc, reference)
    return "accepted"


REFERENCES = ["gripper.scxml", "/gripper.scxml", "http://127.0.0.1:8000/x.scxml", "file:///etc/passwd",
              "/etc/passwd", "http://10.0.0.1/x", "//evil.example/x", "http://127.0.0.1@evil/x", "http://[::1]/x",
              "http://127.0.0.1:99999/x", "http://[zz/x", "javascript:alert(1)", "\\\\host\\share", "..\\..\\x",
              "http://127.0.0.1/%00", "http://127.0.0.1\u3002evil/x", "ftp://127.0.0.1/x", "data:text/plain,x", ""]


# ---------------------------------------------------------------------------------------------------------------
# UPnP root descriptions and SSDP messages, in process

LOCATION = "http://127.0.0.1:8000/dev/description.xml"
"""Where the fuzzed device says its description is (and the host it is trusted for)."""


def _free_udp_port() -> int:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


@functools.cache
def upnp_seeds() -> tuple[bytes, bytes]:
    """The root description and the service description (SCPD) of a real device server, fetched over loopback."""
    import asyncio
    import urllib.request
    from collections.abc import Mapping
    from typing import Any
    from urllib.parse import urljoin

    from lxml import etree

    from plugnproduce.protocols.upnp import (
        DeviceFiles,
        SsdpNetwork,
        UpnpDeviceServer,
        device_type_for,
        service_spec_from_chart_events,
    )

    async def answer(action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        return {"Result": "accepted"}

    def get(url: str) -> bytes:
        with urllib.request.urlopen(url, timeout=10) as response:  # noqa: S310 - a loopback URL of our own server
            return bytes(response.read())

    async def fetch() -> tuple[bytes, bytes]:
        folder = DESCRIPTIONS / "devices"
        files = DeviceFiles("sensor3d.ttl", (folder / "sensor3d.ttl").read_text(), "sensor3d.scxml",
                            (folder / "sensor3d.scxml").read_text())
        spec = service_spec_from_chart_events({"Capture": ["Exposure"]}, ["CaptureDone"])
        server = UpnpDeviceServer("sensor3d", "3D sensor", device_type_for("StereoCamera"), spec, answer,
                                  files=files, network=SsdpNetwork(port=_free_udp_port()))
        async with server:
            assert server.location is not None
            root = await asyncio.to_thread(get, server.location)
            scpd_url = etree.fromstring(root).findtext(".//{urn:schemas-upnp-org:device-1-0}SCPDURL") or ""
            scpd = await asyncio.to_thread(get, urljoin(server.location, scpd_url))
        return root, scpd

    return asyncio.run(fetch())


def run_upnp_description(root: bytes, scpd: bytes) -> str:
    """A device's root description and SCPD as the controller reads them when it connects (trust rule included)."""
    import asyncio

    from async_upnp_client.client import UpnpRequester
    from async_upnp_client.const import HttpRequest, HttpResponse
    from async_upnp_client.utils import CaseInsensitiveDict

    from plugnproduce.protocols.upnp import UpnpDeviceClient
    from plugnproduce.protocols.upnp.boundary import TrustedRequester
    from plugnproduce.protocols.upnp.client import load_device

    class Served(UpnpRequester):
        """Answers the description URL with ``root`` and every other URL with ``scpd``."""

        async def async_http_request(self, http_request: HttpRequest) -> HttpResponse:
            body = root if http_request.url == LOCATION else scpd
            return HttpResponse(200, CaseInsensitiveDict(), body.decode("utf-8", "replace"))

    async def connect() -> None:
        requester = TrustedRequester(Served(), "127.0.0.1", "device uuid:fuzz")
        UpnpDeviceClient(await load_device(LOCATION, requester, "device uuid:fuzz", 5.0), requester, 5.0)

    try:
        asyncio.run(connect())
    except ProtocolError as exc:
        return _refused(exc, root + b"\n" + scpd)
    return "accepted"


def ssdp_seeds() -> list[bytes]:
    """An alive, a byebye and a search answer of a device, as async-upnp-client's device server sends them."""
    usn = "uuid:2fac1234-31f8-11b4-a222-08002b34c003::urn:schemas-plugnproduce-org:service:DeviceControl:1"
    common = f"HOST: 239.255.255.250:1900\r\nUSN: {usn}\r\n"
    alive = (f"NOTIFY * HTTP/1.1\r\n{common}CACHE-CONTROL: max-age=1800\r\nLOCATION: {LOCATION}\r\n"
             "NT: urn:schemas-plugnproduce-org:service:DeviceControl:1\r\nNTS: ssdp:alive\r\n"
             "SERVER: Linux/6 UPnP/2.0 plugnproduce/1\r\n\r\n")
    byebye = (f"NOTIFY * HTTP/1.1\r\n{common}NT: urn:schemas-plugnproduce-org:service:DeviceControl:1\r\n"
              "NTS: ssdp:byebye\r\n\r\n")
    answer = (f"HTTP/1.1 200 OK\r\nCACHE-CONTROL: max-age=1800\r\nEXT:\r\nLOCATION: {LOCATION}\r\n"
              f"SERVER: Linux/6 UPnP/2.0 plugnproduce/1\r\nST: urn:schemas-plugnproduce-org:service:DeviceControl:1\r\n"
              f"USN: {usn}\r\n\r\n")
    return [alive.encode(), byebye.encode(), answer.encode()]


def run_ssdp(data: bytes) -> str:
    """One SSDP datagram from 127.0.0.1 through async-upnp-client's parsing to the listener and the search.

    What either reports must carry a UDN and a source, and a description URL naming another host
    than the sender, or no HTTP URL at all, is refused by the trust rule with one line.
    """
    import asyncio

    from aiohttp.http_exceptions import BadHttpMessage
    from async_upnp_client.advertisement import SsdpAdvertisementListener
    from async_upnp_client.search import SsdpSearchListener
    from async_upnp_client.ssdp import decode_ssdp_packet, is_valid_ssdp_packet

    from plugnproduce.protocols.upnp import AdvertisementListener, DeviceSearch
    from plugnproduce.protocols.upnp.boundary import check_trusted

    if not is_valid_ssdp_packet(data):
        return "refused"
    try:
        request_line, headers = decode_ssdp_packet(data, ("127.0.0.1", 1900), ("127.0.0.1", 50000))
    except (BadHttpMessage, ValueError):  # dropped: async-upnp-client's receiver drops an InvalidHeader, discovery the rest
        return "refused"

    async def deliver() -> list[tuple[str, str | None, str]]:
        listener, search = AdvertisementListener(), DeviceSearch()
        ads = SsdpAdvertisementListener(on_alive=listener._on_alive, on_byebye=listener._on_byebye)
        ads._on_data(request_line, headers.copy())  # noqa: SLF001 - the library's own entry for a datagram
        answers = SsdpSearchListener(callback=search._on_response)
        answers._on_data(request_line, headers.copy())  # noqa: SLF001
        return [(a.udn, a.location, a.source_host) for a in listener.seen] + \
            [(h.udn, h.location, h.source_host) for h in search.hits.values()]

    reported = asyncio.run(deliver())
    for udn, location, host in reported:
        if not (isinstance(udn, str) and udn and isinstance(host, str) and host):
            raise Crash(f"SSDP report without a UDN or source: {udn!r} from {host!r}")
        if location is not None:
            try:
                check_trusted(location, host, f"device {excerpt(udn)} at {excerpt(location)}")  # as describe() does
            except ProtocolError as exc:
                return _refused(exc, data)
    return "accepted" if reported else "refused"


# ---------------------------------------------------------------------------------------------------------------
# HMI requests, in process


class InProcessHmi:
    """The HMI application over the simulated bin-picking cell, called in process from synchronous code.

    The application and its lifespan live on an event loop in a thread of their own; each request
    is an ``httpx`` call through ``ASGITransport`` from a loopback client address.
    """

    TOKEN = "fuzz-token-0123456789abcdef"

    def __init__(self, runs: Path) -> None:
        import asyncio
        import threading

        import httpx

        from plugnproduce import service
        from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app

        source = SimulatedCellSource(service.cell(service.builtin("cells", "bin-picking.yaml")), service.catalogue())
        self.app = create_app(source, ExecutorRunner(source, runs), self.TOKEN)
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="fuzz-hmi", daemon=True)
        self._thread.start()
        self._lifespan = self.app.router.lifespan_context(self.app)
        self._call(self._lifespan.__aenter__())
        transport = httpx.ASGITransport(app=self.app, client=("127.0.0.1", 50000))
        self.client = httpx.AsyncClient(transport=transport, base_url="http://127.0.0.1")

    def _call(self, coroutine: object) -> object:
        import asyncio

        return asyncio.run_coroutine_threadsafe(coroutine, self._loop).result(60)  # type: ignore[arg-type]

    def request(self, method: str, url: str, **kwargs: object) -> object:
        """One request; returns the ``httpx.Response``."""
        return self._call(self.client.request(method, url, **kwargs))  # type: ignore[arg-type]

    def close(self) -> None:
        """Leave the lifespan (the simulated devices stop) and the loop."""
        self.app.state.hub.close_streams()
        self._call(self.client.aclose())
        self._call(self._lifespan.__aexit__(None, None, None))
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(10)
        self._loop.close()


def hmi_requests() -> list[tuple[str, str, dict[str, object]]]:
    """Valid requests that only read or check, as the page sends them: the seeds of the HMI fuzzing."""
    task = {"name": "bin-picking", "repeat": 2, "steps": [
        {"command": "bin-pick", "bind": {"robot": "robot", "gripper": "gripper"},
         "params": {"grip_force": 45, "exposure": 25, "part_type": "bracket"}},
        {"command": "place", "params": {"place_pose": [0.6, -0.2, 0.1, 0, 180, 0], "speed": 80}}]}
    yaml_task = (DESCRIPTIONS / "tasks" / "bin-picking.yaml").read_bytes()
    return [
        ("POST", "/api/task/validate", {"json": task}),
        ("POST", "/api/task/export", {"json": task}),
        ("POST", "/api/task/import", {"content": yaml_task, "headers": {"content-type": "application/yaml"}}),
        ("GET", "/api/processes/pick", {}),
        ("GET", "/api/charts/process/pick.svg", {}),
        ("GET", "/api/runs/unknown", {}),
        ("POST", "/api/runs", {"json": {"task": task}}),  # no token: refused before anything runs
    ]


def _mutate_json(value: object, rng: random.Random, depth: int = 0) -> object:
    """A JSON value with one part replaced by something hostile."""
    hostile: list[object] = [None, True, -1, 0, 10**40, -(10**40), 1e308, "NaN", "x" * 5000, [], {}, [[[[[]]]]],
                             {"a": {"b": {"c": 1}}}, "\u0000", "\ud7ff\ue000", 2**63, -0.0, 1e-320, "../../etc/passwd",
                             [1] * 10_001, {"command": "pick"}]
    if isinstance(value, dict) and value and rng.random() < 0.8:
        key = rng.choice(list(value))
        out = dict(value)
        if rng.random() < 0.15:
            out[rng.choice(["extra", "task", "x" * 300, ""])] = rng.choice(hostile)
        elif rng.random() < 0.1:
            del out[key]
        else:
            out[key] = _mutate_json(value[key], rng, depth + 1)
        return out
    if isinstance(value, list) and value and rng.random() < 0.8:
        out_list = list(value)
        i = rng.randrange(len(out_list))
        if rng.random() < 0.1:
            out_list = out_list * rng.choice([2, 50, 2000])
        else:
            out_list[i] = _mutate_json(out_list[i], rng, depth + 1)
        return out_list
    return rng.choice(hostile)


def mutate_request(seed: tuple[str, str, dict[str, object]], rng: random.Random) -> tuple[str, str, dict[str, object]]:
    """A request of the page damaged: its JSON body, its YAML body, its path or its content type."""
    method, url, kwargs = seed
    kwargs = dict(kwargs)
    if "json" in kwargs and rng.random() < 0.85:
        if rng.random() < 0.2:
            import json

            raw = json.dumps(kwargs.pop("json")).encode()
            kwargs["content"] = mutate(raw, rng)
            kwargs["headers"] = {"content-type": "application/json"}
        else:
            kwargs["json"] = _mutate_json(kwargs["json"], rng)
    elif "content" in kwargs and rng.random() < 0.85:
        kwargs["content"] = mutate(kwargs["content"], rng)  # type: ignore[arg-type]
        if rng.random() < 0.1:
            kwargs["headers"] = {"content-type": rng.choice(["text/plain", "application/x-www-form-urlencoded", ""])}
    else:
        from urllib.parse import quote

        part = mutate(url.rsplit("/", 1)[1].encode(), rng).decode("latin-1")[:2000]  # a client sends no longer URL
        url = url.rsplit("/", 1)[0] + "/" + quote(part, safe="")
    return method, url, kwargs


def run_hmi(hmi: InProcessHmi, request: tuple[str, str, dict[str, object]]) -> str:
    """One request: any status below 500, and an error's ``detail`` text is one short line."""
    import json

    method, url, kwargs = request
    response = hmi.request(method, url, **kwargs)
    status = response.status_code  # type: ignore[attr-defined]
    if status >= 500:
        raise Crash(f"HTTP {status} for {method} {url[:100]}: {response.text[:300]!r}")  # type: ignore[attr-defined]
    if status < 400:
        return "accepted"
    try:
        detail = response.json().get("detail")  # type: ignore[attr-defined]
    except (ValueError, AttributeError) as exc:
        raise Crash(f"HTTP {status} for {method} {url[:100]} without a JSON error") from exc
    sent = kwargs.get("content") or json.dumps(kwargs.get("json", "")).encode()
    if isinstance(detail, str):
        check_message(detail, sent)  # type: ignore[arg-type]
    elif isinstance(detail, list):  # pydantic's list of field errors
        for item in detail:
            check_message(str(item.get("msg", "")), sent)  # type: ignore[arg-type]
    return "refused"
