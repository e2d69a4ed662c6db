"""XIRP under stress, over real loopback sockets: hostile input, time-outs, lost connections.

Every server binds port 0; nothing sleeps to synchronise: every wait is for a
condition (a response, the end of a connection), bounded by a timeout.
"""

from __future__ import annotations

import asyncio
import dataclasses
import socket
from collections.abc import AsyncIterator, Callable
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.errors import ProtocolConnectionError, ProtocolError, ProtocolTimeout
from plugnproduce.executor.links import open_link
from plugnproduce.protocols.xirp import (
    MAX_FRAME,
    NAMESPACE,
    Bye,
    ErrorMessage,
    Hello,
    Message,
    Request,
    Response,
    Value,
    XirpClient,
    XirpServer,
    decode,
    encode_frame,
    frame,
)
from tests.lines import WAIT

HOST = "127.0.0.1"
ROBOT = "http://plugnproduce.org/ontology#Robot"


def echo(request: Request) -> dict[str, Value]:
    """A device that answers every request with its own parameters."""
    return dict(request.params)


@pytest.fixture
async def server() -> AsyncIterator[XirpServer]:
    async with XirpServer("robot", ROBOT, echo) as device:
        yield device


class RawPeer:
    """A hand-driven TCP connection to a device, for sending what no XirpClient would."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer

    @classmethod
    async def connect(cls, port: int) -> RawPeer:
        reader, writer = await asyncio.open_connection(HOST, port)
        return cls(reader, writer)

    def send(self, data: bytes) -> None:
        self.writer.write(data)

    async def receive(self) -> Message:
        async with asyncio.timeout(WAIT):
            length = int.from_bytes(await self.reader.readexactly(4), "big")
            return decode(await self.reader.readexactly(length))

    async def closed_by_peer(self) -> bool:
        async with asyncio.timeout(WAIT):
            return await self.reader.read(1) == b""

    async def close(self) -> None:
        self.writer.close()
        await self.writer.wait_closed()


@pytest.fixture
async def raw(server: XirpServer) -> AsyncIterator[RawPeer]:
    peer = await RawPeer.connect(server.port)
    assert isinstance(await peer.receive(), Hello)
    yield peer
    await peer.close()


async def until(condition: Callable[[], bool]) -> None:
    """Wait (bounded) until ``condition()`` holds; for states no awaitable announces."""
    async with asyncio.timeout(WAIT):
        while not condition():
            await asyncio.sleep(0.001)


# ---------------------------------------------------------------- hostile and broken input


async def test_a_malformed_message_gets_an_error_and_the_device_keeps_serving(server: XirpServer, raw: RawPeer) -> None:
    raw.send(frame(f'<request xmlns="{NAMESPACE}" id="5" name="Open"'.encode()))
    error = await raw.receive()
    assert isinstance(error, ErrorMessage)
    assert (error.code, error.ref) == ("malformed", "5")
    raw.send(encode_frame(Request("6", "Open")))  # the same connection still works
    assert await raw.receive() == Response("6")
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as second:
        assert await second.request("Open") == {}


@pytest.mark.parametrize(
    "document",
    [
        b"",
        b"\xff\xfe not UTF-8",
        f'<!DOCTYPE r [<!ENTITY a "aaaa">]><request xmlns="{NAMESPACE}" id="1" name="&a;"/>'.encode(),
        f'<request xmlns="{NAMESPACE}" id="1" name="Open"><foo/></request>'.encode(),
        b'<request id="1" name="Open"/>',
    ],
    ids=["empty", "binary", "doctype", "invalid", "no namespace"],
)
async def test_hostile_documents_are_answered_with_errors(raw: RawPeer, document: bytes) -> None:
    raw.send(frame(document))
    error = await raw.receive()
    assert isinstance(error, ErrorMessage) and error.code == "malformed"


async def test_an_unexpected_message_is_answered_with_an_error(raw: RawPeer) -> None:
    raw.send(encode_frame(Hello("impostor", ROBOT)))
    error = await raw.receive()
    assert isinstance(error, ErrorMessage)
    assert error.code == "unexpected" and "hello" in error.text


async def test_an_oversized_frame_closes_that_connection_only(server: XirpServer, raw: RawPeer) -> None:
    raw.send((MAX_FRAME + 1).to_bytes(4, "big") + b"<" * 1000)
    error = await raw.receive()
    assert isinstance(error, ErrorMessage)
    assert error.code == "too-large" and str(MAX_FRAME) in error.text
    assert await raw.closed_by_peer()
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as second:
        assert await second.request("Open") == {}


async def test_a_frame_split_into_pieces_is_put_back_together(raw: RawPeer) -> None:
    data = encode_frame(Request("9", "Close", {"GripForce": 12.5})) + encode_frame(Request("10", "Open"))
    for i in range(0, len(data), 7):
        raw.send(data[i : i + 7])
        await raw.writer.drain()
    assert await raw.receive() == Response("9", {"GripForce": 12.5})
    assert await raw.receive() == Response("10")


async def test_a_controller_saying_bye_is_let_go(server: XirpServer, raw: RawPeer) -> None:
    raw.send(encode_frame(Request("1", "Open")) + encode_frame(Bye("done")) + encode_frame(Request("2", "Open")))
    assert await raw.receive() == Response("1")
    assert await raw.closed_by_peer()  # nothing after the bye is answered
    await until(lambda: server.connections == 0)


# ---------------------------------------------------------------- time-outs and lost connections


async def test_a_request_without_response_in_time_is_a_timeout() -> None:
    release = asyncio.Event()

    async def slow(request: Request) -> None:
        await release.wait()

    async with XirpServer("robot", ROBOT, slow) as device:
        async with await XirpClient.connect(HOST, device.port, timeout=WAIT) as controller:
            with pytest.raises(ProtocolTimeout, match="request Wait to device 'robot'.*no response within 0.05 s"):
                await controller.request("Wait", timeout=0.05)
            release.set()  # the late response arrives and is ignored
            assert await controller.request("Wait") == {}
            assert controller.connected


async def test_a_lost_connection_fails_waiting_requests_and_is_reported() -> None:
    started, release = asyncio.Event(), asyncio.Event()

    async def stuck(request: Request) -> None:
        started.set()
        await release.wait()

    async with XirpServer("robot", ROBOT, stuck) as device:
        controller = await XirpClient.connect(HOST, device.port, timeout=WAIT)
        waiting = asyncio.create_task(controller.request("Wait"))
        async with asyncio.timeout(WAIT):
            await started.wait()
        assert await device.disconnect_all() == 1
        with pytest.raises(ProtocolConnectionError, match="connection lost"):
            await waiting
        async with asyncio.timeout(WAIT):
            await controller.wait_closed()
        assert not controller.connected
        assert controller.lost is not None and "device 'robot'" in str(controller.lost)
        with pytest.raises(ProtocolConnectionError):
            await controller.next_event()
        with pytest.raises(ProtocolConnectionError):
            await controller.request("Wait")
        await controller.close()
        release.set()


async def test_a_stopping_device_says_bye() -> None:
    device = XirpServer("robot", ROBOT, echo)
    await device.start()
    controller = await XirpClient.connect(HOST, device.port, timeout=WAIT)
    await device.stop("maintenance")
    async with asyncio.timeout(WAIT):
        await controller.wait_closed()
    assert controller.lost is not None and "said bye (maintenance)" in str(controller.lost)
    await controller.close()
    await device.stop()  # a second stop is harmless


async def test_nothing_listening_is_a_connection_error() -> None:
    with socket.socket() as sock:
        sock.bind((HOST, 0))
        port = sock.getsockname()[1]  # bound, not listening: connections are refused
        with pytest.raises(ProtocolConnectionError, match=f"xirp://{HOST}:{port}: cannot connect"):
            await XirpClient.connect(HOST, port, timeout=WAIT)


async def _fake_device(behaviour: Callable[[asyncio.StreamWriter], Any]) -> tuple[asyncio.Server, int]:
    async def serve(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        behaviour(writer)
        await reader.read()  # until the controller leaves
        writer.close()

    fake = await asyncio.start_server(serve, HOST, 0)
    return fake, fake.sockets[0].getsockname()[1]


async def test_a_device_that_never_says_hello_is_a_timeout() -> None:
    fake, port = await _fake_device(lambda writer: None)
    async with fake:
        with pytest.raises(ProtocolTimeout, match="no connection and hello within 0.1 s"):
            await XirpClient.connect(HOST, port, timeout=0.1)


async def test_a_device_slower_to_greet_than_its_command_timeout_is_still_connected() -> None:
    """Opening a link waits for the greeting longer than a command (the gripper's 2 s): a busy device host is
    not a lost device."""
    async def greet_late(writer: asyncio.StreamWriter) -> None:
        await asyncio.sleep(0.5)
        writer.write(encode_frame(Hello("gripper", ROBOT)))

    fake, port = await _fake_device(lambda writer: asyncio.ensure_future(greet_late(writer)))
    gripper = dataclasses.replace(service.cell(service.builtin("cells", "bin-picking.yaml")).device("gripper"),
                                  endpoint=f"xirp://{HOST}:{port}", command_timeout=0.05)
    async with fake:
        link = await open_link(gripper, lambda *_: None, lambda *_: None, lambda *_: None)
        assert link.device == "gripper"
        await link.close()


async def test_a_device_that_greets_with_something_else_is_refused() -> None:
    fake, port = await _fake_device(lambda writer: writer.write(encode_frame(Response("1"))))
    async with fake:
        with pytest.raises(ProtocolError, match="first message is a Response; expected hello"):
            await XirpClient.connect(HOST, port, timeout=WAIT)


async def test_a_device_sending_an_oversized_frame_is_dropped() -> None:
    hello = encode_frame(Hello("big", ROBOT))
    fake, port = await _fake_device(lambda writer: writer.write(hello + (2 * MAX_FRAME).to_bytes(4, "big")))
    async with fake:
        controller = await XirpClient.connect(HOST, port, timeout=WAIT)
        async with asyncio.timeout(WAIT):
            await controller.wait_closed()
        assert controller.lost is not None and "at most 65536 are accepted" in str(controller.lost)
        await controller.close()


async def test_a_controller_running_far_ahead_is_answered_in_order() -> None:
    """Requests queue behind a slow asynchronous handler; reading pauses and resumes; none is lost."""
    started, release = asyncio.Event(), asyncio.Event()

    async def handler(request: Request) -> dict[str, Value]:
        if request.name == "First":
            started.set()
            await release.wait()
        return {"N": request.params.get("N", 0)}

    async with XirpServer("robot", ROBOT, handler) as device:
        async with await XirpClient.connect(HOST, device.port, timeout=WAIT) as controller:
            first = asyncio.create_task(controller.request("First"))
            rest = [asyncio.create_task(controller.request("Next", {"N": n})) for n in range(200)]
            async with asyncio.timeout(WAIT):
                await started.wait()
            (connection,) = device._connections  # white box: wait until reading has paused
            await until(lambda: len(connection._frames) >= 64)
            release.set()
            assert await first == {"N": 0}
            assert [r["N"] for r in await asyncio.gather(*rest)] == list(range(200))


# ---------------------------------------------------------------- a device flooding the controller


def _raw_frame(document: str) -> bytes:
    data = document.encode()
    return len(data).to_bytes(4, "big") + data


async def test_an_event_with_an_overlong_sequence_number_is_malformed_and_the_connection_lives() -> None:
    hello = encode_frame(Hello("robot", ROBOT))
    huge = _raw_frame(f'<event xmlns="{NAMESPACE}" name="moved" seq="{"9" * 5000}" time="2026-01-01T00:00:00Z"/>')
    fine = _raw_frame(f'<event xmlns="{NAMESPACE}" name="moved" seq="1" time="2026-01-01T00:00:00Z"/>')
    fake, port = await _fake_device(lambda writer: writer.write(hello + huge + fine))
    async with fake, await XirpClient.connect(HOST, port, timeout=WAIT) as controller:
        event = await controller.next_event()
        assert (event.name, event.seq) == ("moved", 1)
        assert controller.stats.malformed == 1
        assert controller.connected


async def test_a_flood_of_unsolicited_errors_is_counted_kept_bounded_and_logged_sparingly(
    caplog: pytest.LogCaptureFixture,
) -> None:
    hello = encode_frame(Hello("robot", ROBOT))
    flood = b"".join(encode_frame(ErrorMessage("failed", f"complaint {n}")) for n in range(3000))
    fake, port = await _fake_device(lambda writer: writer.write(hello + flood))
    async with fake, await XirpClient.connect(HOST, port, timeout=WAIT) as controller:
        await until(lambda: controller.stats.reported == 3000)
        assert len(controller.stats.errors) <= 64
        assert controller.stats.errors[-1].text == "complaint 2999"
        assert controller.connected
    complaints = [r for r in caplog.records if "complaint" in r.getMessage()]
    assert 0 < len(complaints) <= 10
