"""Benchmark: an OPC UA request round trip through the controller against a plain asyncua method call.

Run ``python bench/bench_opcua.py [--iterations N] [--rounds R]``. One process, one event loop, both
clients connected side by side to the same simulated device (``binpicking-pc-ua``, an asyncua server
running its device chart on loopback), whose ``Localize`` answers at once with its output arguments:

* plain asyncua (the baseline): ``Node.call_method(method, Variant("bracket"))`` from an asyncua ``Client``,
  the method node found once beforehand (calling by browse name would translate the path on every call and
  flatter the controller, which finds it once);
* the controller: ``OpcUaLink.request("Localize", {"PartType": "bracket"})``, the executor's link: the
  method's input arguments read once, the argument checked and typed, the call, the output arguments held
  to the limits and handed on as the device's answer event.

Both take the same server-side path (the chart takes the request and answers), so the ratio is the
controller's own overhead. They run in alternating blocks (``R`` rounds of ``N / R`` calls each), so a change
of machine load hits both alike. Prints the median and 99th percentile of each and the ratio of the medians
(target ≤ 1.5).
"""

from __future__ import annotations

import argparse
import asyncio
import atexit
import dataclasses
import os
import statistics
import time
from collections.abc import Awaitable, Callable
from pathlib import Path

from asyncua import Client, ua

from plugnproduce.description.loader import load_device
from plugnproduce.executor.links import OpcUaLink
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua import namespace_for
from plugnproduce.sim.device import SimulatedDevice

DEVICE = Path(__file__).resolve().parents[1] / "descriptions" / "devices" / "binpicking-pc-ua.ttl"
WARM_UP = 50
BASELINE = "plain asyncua"


async def _timed(call: Callable[[], Awaitable[object]], count: int, into: list[float]) -> None:
    for _ in range(count):
        start = time.perf_counter()
        await call()
        into.append((time.perf_counter() - start) * 1e6)


async def measure(iterations: int, rounds: int) -> dict[str, list[float]]:
    """Per kind of call, the round-trip times in µs."""
    device = load_device(DEVICE, load_taxonomy())
    answers: list[object] = []
    async with SimulatedDevice(device) as sim:
        device = dataclasses.replace(device, endpoint=sim.endpoint)
        link = await OpcUaLink.open(device, lambda *a: answers.append(a), lambda *_: None, lambda *_: None)
        async with Client(sim.endpoint) as plain:
            ns = await plain.get_namespace_index(namespace_for(device.id))
            node = await plain.nodes.objects.get_child(f"{ns}:{device.id}")
            method = await node.get_child(f"{ns}:Localize")  # found once, as the link finds it once
            calls: dict[str, Callable[[], Awaitable[object]]] = {
                BASELINE: lambda: node.call_method(method, ua.Variant("bracket", ua.VariantType.String)),
                "controller link": lambda: link.request("Localize", {"PartType": "bracket"}, 10.0),
            }
            times: dict[str, list[float]] = {name: [] for name in calls}
            for call in calls.values():
                await _timed(call, WARM_UP, [])
            for _ in range(rounds):
                for name, call in calls.items():
                    await _timed(call, iterations // rounds, times[name])
        await link.close()
    assert answers, "the link handed on no answer"
    return times


def _summary(samples: list[float]) -> tuple[float, float]:
    return statistics.median(samples), statistics.quantiles(samples, n=100)[98]


async def main(iterations: int, rounds: int) -> float:
    """Run the measurements, print them, return the ratio of the medians (controller / plain asyncua)."""
    times = await measure(iterations, rounds)
    base_median, base_p99 = _summary(times[BASELINE])
    print(f"{iterations // rounds * rounds} method calls each, {rounds} alternating blocks")
    ratio = 0.0
    for name, samples in times.items():
        median, p99 = _summary(samples)
        line = f"{name:16} median {median:8.1f} µs   p99 {p99:8.1f} µs"
        if name != BASELINE:
            ratio = median / base_median
            line += f"   ratio to plain asyncua: median {ratio:4.2f}, p99 {p99 / base_p99:4.2f} (target ≤ 1.5)"
        print(line)
    return ratio


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--iterations", type=int, default=1000, help="method calls of each kind (default 1000)")
    parser.add_argument("--rounds", type=int, default=10, help="alternating blocks (default 10)")
    arguments = parser.parse_args()
    asyncio.run(main(arguments.iterations, arguments.rounds))
