"""Fault injection on the device side: each fault rule, over real loopback sockets."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator

import pytest

from plugnproduce.errors import ProtocolConnectionError, ProtocolTimeout
from plugnproduce.protocols.xirp import (
    Event,
    FaultKind,
    FaultRule,
    Faults,
    MessageError,
    RemoteFailure,
    Request,
    XirpClient,
    XirpServer,
)
from tests.lines import WAIT

HOST = "127.0.0.1"
SHORT = 0.1  # a time-out the tests expect to run out


class Recorder:
    def __init__(self) -> None:
        self.calls: list[str] = []

    def __call__(self, request: Request) -> dict[str, str]:
        self.calls.append(request.name)
        return {"Result": f"done {request.name}"}


@pytest.fixture
def recorder() -> Recorder:
    return Recorder()


@pytest.fixture
async def server(recorder: Recorder) -> AsyncIterator[XirpServer]:
    async with XirpServer("gripper", "http://plugnproduce.org/ontology#ParallelGripper", recorder) as device:
        yield device


@pytest.fixture
async def client(server: XirpServer) -> AsyncIterator[XirpClient]:
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as controller:
        yield controller


# ---------------------------------------------------------------- requests


async def test_drop_response_handles_the_request_but_sends_no_answer(
    server: XirpServer, client: XirpClient, recorder: Recorder
) -> None:
    server.faults.add(FaultKind.DROP_RESPONSE, "Open")
    with pytest.raises(ProtocolTimeout, match="no response within"):
        await client.request("Open", timeout=SHORT)
    assert recorder.calls == ["Open"]
    assert await client.request("Open") == {"Result": "done Open"}  # fired once only
    assert server.faults.fired == [(FaultKind.DROP_RESPONSE, "Open")]


async def test_error_response_answers_with_the_rules_failure(
    server: XirpServer, client: XirpClient, recorder: Recorder
) -> None:
    server.faults.add(FaultKind.ERROR_RESPONSE, "Close", code="jammed", text="the jaws are stuck")
    with pytest.raises(RemoteFailure) as caught:
        await client.request("Close")
    assert (caught.value.code, caught.value.text) == ("jammed", "the jaws are stuck")
    assert recorder.calls == []  # the device did not act


async def test_malformed_response_sends_garbage_instead(
    server: XirpServer, client: XirpClient, recorder: Recorder
) -> None:
    server.faults.add(FaultKind.MALFORMED_RESPONSE, "Open")
    with pytest.raises(ProtocolTimeout):
        await client.request("Open", timeout=SHORT)
    assert recorder.calls == ["Open"]
    assert client.stats.malformed == 1
    assert client.connected  # garbage is reported, not fatal
    assert await client.request("Open") == {"Result": "done Open"}


async def test_disconnect_drops_the_connection_without_bye(
    server: XirpServer, client: XirpClient, recorder: Recorder
) -> None:
    server.faults.add(FaultKind.DISCONNECT, "MoveTo")
    with pytest.raises(ProtocolConnectionError, match="request MoveTo"):
        await client.request("MoveTo")
    async with asyncio.timeout(WAIT):
        await client.wait_closed()
    assert client.lost is not None and "bye" not in str(client.lost)
    assert recorder.calls == []
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as again:  # the device still listens
        assert await again.request("MoveTo") == {"Result": "done MoveTo"}


async def test_a_rule_without_name_hits_any_request_and_times_none_every_time(
    server: XirpServer, client: XirpClient
) -> None:
    server.faults.add(FaultKind.ERROR_RESPONSE, times=None)
    for name in ("Open", "Close", "Open"):
        with pytest.raises(RemoteFailure):
            await client.request(name)
    server.faults.clear()
    assert await client.request("Open") == {"Result": "done Open"}
    assert [name for _kind, name in server.faults.fired] == ["Open", "Close", "Open"]


async def test_faults_given_at_construction_are_used(recorder: Recorder) -> None:
    faults = Faults([FaultRule(FaultKind.ERROR_RESPONSE, "Open", code="busy")])
    async with XirpServer("g", "http://x/#G", recorder, faults=faults) as device:
        async with await XirpClient.connect(HOST, device.port, timeout=WAIT) as controller:
            with pytest.raises(RemoteFailure, match="busy"):
                await controller.request("Open")
    assert device.faults is faults


async def test_disconnect_all_is_a_crash_seen_by_every_controller(server: XirpServer, client: XirpClient) -> None:
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as other:
        assert await server.disconnect_all() == 2
        async with asyncio.timeout(WAIT):
            await asyncio.gather(client.wait_closed(), other.wait_closed())
        assert client.lost is not None and other.lost is not None
    assert server.connections == 0


# ---------------------------------------------------------------- events


async def test_drop_event_uses_up_its_number(server: XirpServer, client: XirpClient) -> None:
    server.faults.add(FaultKind.DROP_EVENT, "a")
    server.emit("a")
    server.emit("b")
    event = await client.next_event()
    assert (event.name, event.seq) == ("b", 2)


async def test_delay_event_lets_later_events_overtake_it(server: XirpServer, client: XirpClient) -> None:
    server.faults.add(FaultKind.DELAY_EVENT, "slow", delay=SHORT)
    server.emit("slow")
    server.emit("fast")
    first, second = await client.next_event(), await client.next_event()
    assert [(first.name, first.seq), (second.name, second.seq)] == [("fast", 2), ("slow", 1)]
    assert second.time <= first.time  # stamped when emitted, not when sent


async def test_duplicate_event_is_sent_twice_and_the_controller_drops_the_copy(server: XirpServer) -> None:
    received: list[Event] = []
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT, on_event=received.append) as controller:
        server.faults.add(FaultKind.DUPLICATE_EVENT, "closed")
        server.emit("closed")
        server.emit("opened")
        await controller.request("Open")  # both copies came before this response
        assert [(e.name, e.seq) for e in received] == [("closed", 1), ("opened", 2)]
        assert controller.stats.duplicates == 1


async def test_malformed_event_is_counted_and_answered_with_an_error(server: XirpServer, client: XirpClient) -> None:
    server.faults.add(FaultKind.MALFORMED_EVENT, payload=b"<event>not XIRP</event>")
    server.emit("closed")
    server.emit("opened")
    assert (await client.next_event()).name == "opened"
    assert client.stats.malformed == 1
    assert client.connected


# ---------------------------------------------------------------- the rules themselves


def test_rules_fire_in_the_order_they_were_added() -> None:
    faults = Faults()
    specific = faults.add(FaultKind.DROP_RESPONSE, "Open")
    faults.add(FaultKind.DISCONNECT, times=None)
    assert faults.take(frozenset({FaultKind.DROP_RESPONSE, FaultKind.DISCONNECT}), "Open") is specific
    assert specific not in faults.rules  # used up
    taken = faults.take(frozenset({FaultKind.DROP_RESPONSE, FaultKind.DISCONNECT}), "Open")
    assert taken is not None and taken.kind is FaultKind.DISCONNECT
    assert faults.take(frozenset({FaultKind.DROP_EVENT}), "Open") is None


@pytest.mark.parametrize(
    ("kwargs", "complaint"),
    [
        ({"kind": FaultKind.DROP_RESPONSE, "times": 0}, "expected at least 1"),
        ({"kind": FaultKind.DROP_RESPONSE, "delay": 1.0}, "only delay-event takes a delay"),
        ({"kind": FaultKind.DELAY_EVENT, "delay": -1.0}, "of 0 s or more"),
        ({"kind": FaultKind.ERROR_RESPONSE, "code": "Bad Code"}, "not an XIRP error code"),
        ({"kind": "no-such-fault"}, "is not a valid FaultKind"),
    ],
)
def test_a_nonsensical_rule_is_refused(kwargs: dict[str, object], complaint: str) -> None:
    with pytest.raises((MessageError, ValueError), match=complaint):
        FaultRule(**kwargs)  # type: ignore[arg-type]
