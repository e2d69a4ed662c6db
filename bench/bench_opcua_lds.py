"""Benchmark: discovering 50 simulated OPC UA devices through a Local Discovery Server (target under 5 s).

Run ``python bench/bench_opcua_lds.py [--devices 50] [--rounds 3]``. A child process runs an LDS and the
devices (each a real asyncua server running its chart, copies of the built-in nutrunner named ``nutrunner-NN``),
each registered with the LDS. In this process, in alternating rounds:

* plain asyncua (the baseline): FindServers on the LDS, then from every server listed, side by side, its four
  description String variables (the least any client must do to learn the devices);
* the controller: a live cell told of the LDS (``LiveCell(lds=...)``, as ``pnp discover --lds``) until all the
  devices are in it: FindServers, each device's description read within its budget and by the trust rules,
  parsed, validated and reasoned over. Its SSDP port is a private one nobody announces on, so only the LDS
  tells it of the devices.

Prints, per way, the median wall time and CPU time (user+sys of this process) over the rounds, the ratios of
the controller's to the baseline's, and the load average at the start and the end.
"""

from __future__ import annotations

import argparse
import asyncio
import atexit
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Awaitable
from pathlib import Path

from asyncua import Client

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.discovery import LiveCell
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua.discovery import LocalDiscoveryServer, find_servers
from plugnproduce.protocols.opcua.spec import DESCRIPTION_OBJECT, DESCRIPTION_VARIABLES, namespace_for
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.device import SimulatedDevice

DEVICES = Path(__file__).resolve().parents[1] / "descriptions" / "devices"


def _copies(folder: Path, count: int) -> list[Path]:
    """``count`` copies of the built-in nutrunner's description, ``nutrunner-00`` ..., beside its chart."""
    turtle = (DEVICES / "screwdriver-ua.ttl").read_text()
    (folder / "screwdriver-ua.scxml").write_text((DEVICES / "screwdriver-ua.scxml").read_text())
    paths = []
    for i in range(count):
        path = folder / f"nutrunner-{i:02}.ttl"
        path.write_text(re.sub(r"screwdriver-ua(?!\.scxml)", f"nutrunner-{i:02}", turtle))
        paths.append(path)
    return paths


async def _serve(count: int) -> None:
    """The child: an LDS and ``count`` devices registered with it, until stdin closes."""
    lds = LocalDiscoveryServer(port=0)
    await lds.start()
    assert lds.endpoint is not None
    taxonomy = load_taxonomy()
    with tempfile.TemporaryDirectory() as folder:
        devices = [SimulatedDevice(load_device(p, taxonomy), network=private_network(), lds=lds.endpoint)
                   for p in _copies(Path(folder), count)]
        for device in devices:
            await device.start()
        print(lds.endpoint, flush=True)
        await asyncio.get_running_loop().run_in_executor(None, sys.stdin.read)
        for device in devices:
            await device.stop()
    await lds.stop()


async def _plain(lds: str, count: int) -> None:
    servers = await find_servers(lds, 30)
    assert len(servers) == count, servers

    async def read(device: str, url: str) -> int:
        async with Client(url, timeout=30) as client:
            ns = await client.get_namespace_index(namespace_for(device))
            folder = await client.nodes.objects.get_child([f"{ns}:{device}", f"{ns}:{DESCRIPTION_OBJECT}"])
            values = [await (await folder.get_child(f"{ns}:{name}")).read_value() for name in DESCRIPTION_VARIABLES]
            return sum(len(v) for v in values)

    sizes = await asyncio.gather(*(read(device, url) for device, url in servers))
    assert all(sizes), sizes


async def _controller(lds: str, count: int) -> None:
    async with LiveCell(service.knowledge().taxonomy, network=private_network(), lds=lds, search_timeout=60,
                        expected_count=count) as live:
        assert len(live.cell.devices) == count, (live.cell.devices, live.refused)


async def _timed(work: Awaitable[None]) -> tuple[float, float]:
    t, c = time.perf_counter(), time.process_time()
    await work
    return time.perf_counter() - t, time.process_time() - c


async def main(count: int, rounds: int) -> None:
    child = subprocess.Popen([sys.executable, __file__, "--serve", str(count)], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None
        lds = child.stdout.readline().strip()
        assert lds.startswith("opc.tcp://"), "the devices did not come up"
        service.knowledge()  # loaded once, before either is timed
        figures: dict[str, list[tuple[float, float]]] = {"plain asyncua": [], "controller": []}
        print(f"{count} devices up, registered with {lds}", flush=True)
        for _ in range(rounds):
            figures["plain asyncua"].append(await _timed(_plain(lds, count)))
            figures["controller"].append(await _timed(_controller(lds, count)))
            print(f"round: plain {figures['plain asyncua'][-1][0]:.2f} s, controller "
                  f"{figures['controller'][-1][0]:.2f} s", flush=True)
    finally:
        assert child.stdin is not None
        child.stdin.close()
        try:
            child.wait(60)
        except subprocess.TimeoutExpired:
            child.kill()
    medians = {way: (statistics.median(w for w, _ in f), statistics.median(c for _, c in f))
               for way, f in figures.items()}
    for way, (wall, cpu) in medians.items():
        print(f"{way:14} {count} devices: wall {wall:.2f} s, CPU {cpu:.2f} s (median of {rounds})")
    (wall, cpu), (base_wall, base_cpu) = medians["controller"], medians["plain asyncua"]
    print(f"controller / plain asyncua: wall {wall / base_wall:.2f}x, CPU {cpu / base_cpu:.2f}x; "
          f"controller wall {wall:.2f} s (target under 5 s)")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--devices", type=int, default=50)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--serve", type=int, help=argparse.SUPPRESS)
    options = parser.parse_args()
    if options.serve is not None:
        asyncio.run(_serve(options.serve))
        sys.exit(0)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    asyncio.run(main(options.devices, options.rounds))
