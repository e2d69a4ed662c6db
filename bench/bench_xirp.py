"""Benchmark: XIRP command round trip against a TCP echo in the same style, on loopback.

Run ``python bench/bench_xirp.py [--iterations N] [--rounds R]``. One process, one
event loop, connections kept open side by side:

* blocking echo (the floor): a blocking-socket echo, the server in a thread, no event loop;
* callback echo (the baseline): written in XIRP's own style, ``asyncio.Protocol``
  callbacks on both sides. The client writes a payload the size of an XIRP request
  frame and awaits a future; the server's ``data_received`` writes it back; the
  client's ``data_received`` completes the future once the whole payload is back;
* streams echo, for reference: the same over ``asyncio.start_server`` and
  ``StreamReader``/``StreamWriter``, about 1.3x slower than the callback echo, so not
  a fair baseline for a protocol written with callbacks;
* XIRP: ``XirpClient.request("MoveTo", {Target: pose, Speed: decimal})`` to an
  ``XirpServer`` whose handler answers at once (encode, frame, hardened parse and
  XSD validation of the request, request matching, handler dispatch, the response
  back). Measured twice: with a plain-function handler (answered within the
  callback that received the request) and with an ``async def`` handler (answered
  from the connection's task, one event-loop turn later).

They run in alternating blocks (``R`` rounds of ``N / R`` round trips each), so a
change of machine load hits all alike. Prints the median and the 99th percentile
of each, the CPU time per round trip (user+sys of this process, which holds both ends), the
ratios to the callback echo (target ≤ 2.5) and the callback echo's to the floor.
"""

from __future__ import annotations

import argparse
import asyncio
import atexit
import os
import socket
import statistics
import threading
import time
from collections.abc import Awaitable, Callable, Mapping

from plugnproduce.protocols.xirp import Pose, Request, Value, XirpClient, XirpServer, encode_frame

HOST = "127.0.0.1"
PARAMS: dict[str, Value] = {"Target": Pose(0.4, 0.1, 0.2, 0.0, 180.0, 0.0), "Speed": 0.25}
WARM_UP = 200
BASELINE = "callback echo"
FLOOR = "blocking echo"
TARGET = 2.5
"""Most XIRP round trip (plain handler), as a multiple of the callback echo's."""


async def _echo(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    try:
        while data := await reader.read(65536):
            writer.write(data)
    finally:
        writer.close()


class _EchoServer(asyncio.Protocol):
    """Writes back whatever arrives, from the callback that received it."""

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self._transport = transport

    def data_received(self, data: bytes) -> None:
        self._transport.write(data)  # type: ignore[attr-defined]


class _EchoClient(asyncio.Protocol):
    """Completes the waiting future once the whole payload has come back."""

    def __init__(self) -> None:
        self.transport: asyncio.Transport | None = None
        self._expected = 0
        self._received = 0
        self._done: asyncio.Future[None] | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]

    def expect(self, size: int) -> asyncio.Future[None]:
        self._expected, self._received = size, 0
        self._done = asyncio.get_running_loop().create_future()
        return self._done

    def data_received(self, data: bytes) -> None:
        self._received += len(data)
        if self._received >= self._expected and self._done is not None and not self._done.done():
            self._done.set_result(None)


class CallbackEcho:
    """A TCP echo on loopback in ``asyncio.Protocol`` callback style, as XIRP is written."""

    def __init__(self, payload: bytes) -> None:
        self.payload = payload
        self._server: asyncio.Server | None = None
        self._client: _EchoClient | None = None

    async def __aenter__(self) -> CallbackEcho:
        loop = asyncio.get_running_loop()
        self._server = await loop.create_server(_EchoServer, HOST, 0)
        port = self._server.sockets[0].getsockname()[1]
        _, self._client = await loop.create_connection(_EchoClient, HOST, port)
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        if self._client is not None and self._client.transport is not None:
            self._client.transport.close()
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()

    async def round_trip(self) -> None:
        """Write the payload, wait until it is all back."""
        if self._client is None or self._client.transport is None:
            raise RuntimeError("echo not started")
        done = self._client.expect(len(self.payload))
        self._client.transport.write(self.payload)
        await done


class BlockingEcho:
    """The floor: a blocking-socket echo on loopback, the server in a thread, the client a plain ``socket``
    (``sendall``, then ``recv`` until the whole payload is back), no event loop on either side."""

    def __init__(self, payload: bytes) -> None:
        self.payload = payload
        self._listener = socket.create_server((HOST, 0))
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._client: socket.socket | None = None

    def _serve(self) -> None:
        connection, _ = self._listener.accept()
        with connection:
            connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            while data := connection.recv(65536):
                connection.sendall(data)

    async def __aenter__(self) -> BlockingEcho:
        self._thread.start()
        self._client = socket.create_connection(self._listener.getsockname())
        self._client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        if self._client is not None:
            self._client.close()
        self._thread.join(5)
        self._listener.close()

    async def round_trip(self) -> None:
        """Write the payload, block until it is all back (the event loop waits meanwhile)."""
        if self._client is None:
            raise RuntimeError("echo not started")
        self._client.sendall(self.payload)
        left = len(self.payload)
        while left > 0:
            left -= len(self._client.recv(65536))


class StreamsEcho:
    """An asyncio-streams TCP echo on loopback: one connection, a payload written and read back whole."""

    def __init__(self, payload: bytes) -> None:
        self.payload = payload
        self._server: asyncio.Server | None = None
        self._streams: tuple[asyncio.StreamReader, asyncio.StreamWriter] | None = None

    async def __aenter__(self) -> StreamsEcho:
        self._server = await asyncio.start_server(_echo, HOST, 0)
        self._streams = await asyncio.open_connection(HOST, self._server.sockets[0].getsockname()[1])
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        if self._streams is not None:
            self._streams[1].close()
            await self._streams[1].wait_closed()
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()

    async def round_trip(self) -> None:
        """Write the payload, read it back."""
        if self._streams is None:
            raise RuntimeError("echo not started")
        reader, writer = self._streams
        writer.write(self.payload)
        await reader.readexactly(len(self.payload))


def _plain_handler(request: Request) -> Mapping[str, Value]:
    return {}


async def _async_handler(request: Request) -> Mapping[str, Value]:
    return {}


async def _block(call: Callable[[], Awaitable[object]], count: int, into: list[float]) -> None:
    clock = time.perf_counter_ns
    for _ in range(count):
        start = clock()
        await call()
        into.append((clock() - start) / 1000)


async def measure(iterations: int, rounds: int) -> tuple[dict[str, list[float]], dict[str, float]]:
    """Round-trip times (µs) of the echoes and of XIRP requests, in alternating blocks, and the CPU time (s,
    user+sys of this process, both ends of each connection being in it) each kind took in all."""
    payload = encode_frame(Request("1", "MoveTo", PARAMS))
    times: dict[str, list[float]] = {name: [] for name in (BASELINE, FLOOR, "streams echo", "XIRP, plain handler",
                                                           "XIRP, async handler")}
    cpu: dict[str, float] = dict.fromkeys(times, 0.0)
    robot = "http://plugnproduce.org/ontology#Robot"
    async with (
        CallbackEcho(payload) as echo,
        BlockingEcho(payload) as floor,
        StreamsEcho(payload) as streams,
        XirpServer("robot", robot, _plain_handler, host=HOST) as plain,
        XirpServer("robot", robot, _async_handler, host=HOST) as awaited,
        await XirpClient.connect(HOST, plain.port) as plain_client,
        await XirpClient.connect(HOST, awaited.port) as async_client,
    ):
        calls: dict[str, Callable[[], Awaitable[object]]] = {
            BASELINE: echo.round_trip,
            FLOOR: floor.round_trip,
            "streams echo": streams.round_trip,
            "XIRP, plain handler": lambda: plain_client.request("MoveTo", PARAMS),
            "XIRP, async handler": lambda: async_client.request("MoveTo", PARAMS),
        }
        for call in calls.values():
            await _block(call, WARM_UP, [])
        for _ in range(rounds):
            for name, call in calls.items():
                began = time.process_time()
                await _block(call, iterations // rounds, times[name])
                cpu[name] += time.process_time() - began
    return times, cpu


def _summary(times: list[float]) -> tuple[float, float]:
    ordered = sorted(times)
    return statistics.median(ordered), ordered[min(len(ordered) - 1, round(0.99 * len(ordered)))]


async def main(iterations: int, rounds: int) -> float:
    """Run the measurements, print them, return the ratio of the medians (plain handler / callback echo)."""
    times, cpu = await measure(iterations, rounds)
    raw_median, raw_p99 = _summary(times[BASELINE])
    size = len(encode_frame(Request("1", "MoveTo", PARAMS)))
    print(f"request frame {size} bytes; {iterations // rounds * rounds} round trips each, {rounds} alternating blocks")
    ratios = {}
    for name, samples in times.items():
        median, p99 = _summary(samples)
        ratios[name] = median / raw_median
        line = f"{name:20} median {median:6.1f} µs   p99 {p99:6.1f} µs   CPU {1e6 * cpu[name] / len(samples):6.1f} µs"
        if name != BASELINE:
            line += (f"   ratio to callback echo: median {median / raw_median:4.2f}, p99 {p99 / raw_p99:4.2f}, "
                     f"CPU {cpu[name] / cpu[BASELINE]:4.2f}")
        print(line)
    print(f"callback echo / blocking echo: median {raw_median / _summary(times[FLOOR])[0]:4.2f}, "
          f"CPU {cpu[BASELINE] / cpu[FLOOR]:4.2f}")
    print(f"target: XIRP (plain handler) ≤ {TARGET}x the callback echo")
    return ratios["XIRP, plain handler"]


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--iterations", type=int, default=2000, help="round trips of each kind (default 2000)")
    parser.add_argument("--rounds", type=int, default=10, help="alternating blocks (default 10)")
    arguments = parser.parse_args()
    asyncio.run(main(arguments.iterations, arguments.rounds))
