"""The XIRP device and controller sides against each other, over real loopback sockets.

Every server binds port 0; nothing sleeps to synchronise: every wait is for a
condition (a response, an event, the end of a connection), bounded by a timeout.
"""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator

import pytest

from plugnproduce.errors import ProtocolError, ProtocolTimeout, RemoteError
from plugnproduce.protocols.xirp import (
    FAILED,
    MAX_FRAME,
    NOT_ACCEPTED,
    UNKNOWN_REQUEST,
    DeviceFiles,
    Event,
    Hello,
    MessageError,
    Pose,
    RemoteFailure,
    Request,
    RequestFailed,
    Value,
    XirpClient,
    XirpServer,
)
from tests.lines import WAIT

HOST = "127.0.0.1"
GRIPPER = "http://plugnproduce.org/ontology#ParallelGripper"
FILES = DeviceFiles(
    "gripper.ttl",
    "@prefix pnp: <http://plugnproduce.org/ontology#> .\n@prefix dev: <http://plugnproduce.org/devices/> .\n"
    "dev:gripper a pnp:ParallelGripper ; pnp:stateChart <gripper.scxml> .\n",
    "gripper.scxml",
    '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="open"><state id="open"/></scxml>\n',
)


class Gripper:
    """A request handler (a plain function) that records its calls."""

    def __init__(self) -> None:
        self.calls: list[Request] = []

    def __call__(self, request: Request) -> dict[str, Value] | None:
        self.calls.append(request)
        if request.name == "Close":
            return {"Accepted": True, "Force": request.params.get("GripForce", 40.0)}
        if request.name == "Echo":
            return dict(request.params)
        if request.name == "Refuse":
            raise RequestFailed("the gripper is closing; Open is accepted in state closed", NOT_ACCEPTED)
        if request.name == "Crash":
            raise ZeroDivisionError("division by zero in the device")
        return None


@pytest.fixture
def gripper() -> Gripper:
    return Gripper()


@pytest.fixture
async def server(gripper: Gripper) -> AsyncIterator[XirpServer]:
    async with XirpServer("gripper", GRIPPER, gripper, label="Parallel gripper PG-70", files=FILES) as device:
        yield device


@pytest.fixture
async def client(server: XirpServer) -> AsyncIterator[XirpClient]:
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as controller:
        yield controller


# ---------------------------------------------------------------- hello, requests, describe


async def test_the_device_says_hello_with_its_id_class_and_label(server: XirpServer, client: XirpClient) -> None:
    assert client.hello == Hello("gripper", GRIPPER, "Parallel gripper PG-70", "describe")
    assert client.device == "gripper" and client.connected
    assert server.endpoint == f"xirp://{HOST}:{server.port}"
    assert server.port > 0
    assert server.connections == 1


async def test_a_request_gets_its_response_with_typed_values(gripper: Gripper, client: XirpClient) -> None:
    params: dict[str, Value] = {
        "Target": Pose(0.4, 0.1, 0.2, 0, 180, 0),
        "Speed": 0.5,
        "N": 3,
        "Safe": True,
        "Tag": "a&b",
    }
    assert await client.request("Echo", params) == params
    assert await client.request("Close", {"GripForce": 55.0}) == {"Accepted": True, "Force": 55.0}
    assert await client.request("Open") == {}
    assert [(c.name, dict(c.params)) for c in gripper.calls] == [
        ("Echo", params),
        ("Close", {"GripForce": 55.0}),
        ("Open", {}),
    ]
    assert len({c.id for c in gripper.calls}) == 3  # every request has its own id


async def test_the_connect_endpoint_form_reaches_the_device(server: XirpServer) -> None:
    async with await XirpClient.connect_endpoint(server.endpoint, timeout=WAIT) as controller:
        assert controller.hello.device == "gripper"


async def test_describe_returns_the_turtle_description_and_the_chart(client: XirpClient) -> None:
    assert await client.describe() == FILES


async def test_a_device_without_files_says_so(gripper: Gripper) -> None:
    async with XirpServer("robot", GRIPPER, gripper) as device:
        async with await XirpClient.connect(HOST, device.port, timeout=WAIT) as controller:
            assert controller.hello.describe is None
            with pytest.raises(ProtocolError, match="serves no description"):
                await controller.describe()
            with pytest.raises(RemoteFailure) as caught:
                await controller.request("describe")
            assert caught.value.code == UNKNOWN_REQUEST


async def test_a_refused_request_is_a_remote_failure_with_code_and_text(client: XirpClient) -> None:
    with pytest.raises(RemoteError) as caught:
        await client.request("Refuse")
    assert isinstance(caught.value, RemoteFailure)
    assert (caught.value.code, caught.value.request) == (NOT_ACCEPTED, "Refuse")
    assert "accepted in state closed" in caught.value.text


async def test_a_handler_bug_is_a_failure_and_the_connection_goes_on(client: XirpClient) -> None:
    with pytest.raises(RemoteFailure) as caught:
        await client.request("Crash")
    assert caught.value.code == FAILED
    assert "division by zero" in caught.value.text
    assert await client.request("Open") == {}


async def test_without_a_handler_every_request_is_unknown() -> None:
    async with XirpServer("robot", GRIPPER) as device:
        async with await XirpClient.connect(HOST, device.port, timeout=WAIT) as controller:
            with pytest.raises(RemoteFailure) as caught:
                await controller.request("MoveTo")
            assert caught.value.code == UNKNOWN_REQUEST


async def test_an_async_handler_answers_requests_in_order() -> None:
    first_started, release_first = asyncio.Event(), asyncio.Event()
    answered: list[str] = []

    async def handler(request: Request) -> dict[str, Value]:
        if request.name == "First":
            first_started.set()
            await release_first.wait()
        answered.append(request.name)
        return {"Name": request.name}

    async with XirpServer("robot", GRIPPER, handler) as device:
        async with await XirpClient.connect(HOST, device.port, timeout=WAIT) as controller:
            first = asyncio.create_task(controller.request("First"))
            second = asyncio.create_task(controller.request("Second"))
            async with asyncio.timeout(WAIT):
                await first_started.wait()
            release_first.set()
            assert await asyncio.gather(first, second) == [{"Name": "First"}, {"Name": "Second"}]
    assert answered == ["First", "Second"]


async def test_a_parameter_that_cannot_be_sent_fails_before_sending(client: XirpClient, gripper: Gripper) -> None:
    with pytest.raises(MessageError, match="parameter name 'bad name'"):
        await client.request("Echo", {"bad name": 1})
    with pytest.raises(MessageError, match="not a finite number"):
        await client.request("Echo", {"Speed": float("nan")})
    assert gripper.calls == []
    assert await client.request("Open") == {}


# ---------------------------------------------------------------- events


async def test_events_reach_the_controller_numbered_and_timed(server: XirpServer, client: XirpClient) -> None:
    sent = server.emit("gripper_closed", {"GripForce": 40.0})
    server.emit("gripper_opened")
    first, second = await client.next_event(), await client.next_event()
    assert first == sent
    assert (first.name, first.seq, first.params) == ("gripper_closed", 1, {"GripForce": 40.0})
    assert (second.name, second.seq) == ("gripper_opened", 2)
    assert first.time.tzinfo is not None and first.time <= second.time


async def test_events_go_to_every_connected_controller(server: XirpServer, client: XirpClient) -> None:
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT) as other:
        server.emit("homed")
        assert (await client.next_event()).name == "homed"
        assert (await other.next_event()).name == "homed"


async def test_events_can_go_to_a_callback(server: XirpServer) -> None:
    received: list[Event] = []
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT, on_event=received.append) as controller:
        server.emit("a")
        server.emit("b")
        await controller.request("Open")  # the events were sent before the response, on the same connection
    assert [e.name for e in received] == ["a", "b"]


async def test_the_event_iterator_ends_when_the_controller_closes(server: XirpServer, client: XirpClient) -> None:
    server.emit("a")
    names: list[str] = []

    async def read_all() -> None:
        async for event in client.events():
            names.append(event.name)
            if event.name == "a":
                await client.close()

    async with asyncio.timeout(WAIT):
        await read_all()
    assert names == ["a"]


async def test_no_event_in_time_is_a_timeout(client: XirpClient) -> None:
    with pytest.raises(ProtocolTimeout, match="none within 0.05 s"):
        await client.next_event(timeout=0.05)


async def test_a_full_event_buffer_drops_the_oldest(server: XirpServer) -> None:
    async with await XirpClient.connect(HOST, server.port, timeout=WAIT, event_buffer=2) as controller:
        for name in ("a", "b", "c"):
            server.emit(name)
        await controller.request("Open")
        assert [(await controller.next_event()).name for _ in range(2)] == ["b", "c"]
        assert controller.stats.overflowed == 1


async def test_describe_takes_no_parameters(client: XirpClient) -> None:
    with pytest.raises(RemoteFailure) as caught:
        await client.request("describe", {"Verbose": True})
    assert caught.value.code == "bad-parameter"


async def test_a_description_too_large_for_a_frame_is_refused_at_start() -> None:
    big = DeviceFiles("big.ttl", "#" * MAX_FRAME, "big.scxml", "<scxml/>")
    device = XirpServer("big", GRIPPER, files=big)
    with pytest.raises(MessageError, match="at most 65536 fit in a frame") as caught:
        await device.start()
    assert caught.value.code == "too-large"
    await device.stop()  # never started: nothing to do
