"""Benchmark of discovery (prints figures; not a test).

    python bench/bench_discovery.py [--rounds 20]

The simulated bin-picking cell on a private SSDP network on loopback: time until a
live cell has found all four devices (against a live cell that expects nothing and so
waits its whole search window), and, for unplugging and plugging the gripper, the
time until the change is seen and the offered process commands are re-inferred
(target: pick disappears and comes back within 1 s).
"""

from __future__ import annotations

import argparse
import asyncio
import atexit
import os
import statistics
import time

from plugnproduce import controller, service
from plugnproduce.discovery import LiveCell
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.cell import SimulatedCell


async def until(live: LiveCell, kind: str, device: str) -> None:
    while (change := await live.next_change(5)).kind != kind or change.device != device:
        pass


async def main(rounds: int) -> None:
    network = private_network()
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    async with SimulatedCell(cell, network=network) as sim:
        ids = [d.id for d in cell.devices]
        t = time.perf_counter()
        async with LiveCell(service.knowledge().taxonomy, network=network):
            pass
        window = time.perf_counter() - t
        print(f"nothing expected: the whole search window is waited, {window:.2f} s")
        t, c = time.perf_counter(), time.process_time()
        async with LiveCell(service.knowledge().taxonomy, network=network, expected=ids) as live:
            await controller.find_devices(live, ids, 5)
            found, found_cpu = time.perf_counter() - t, time.process_time() - c
            print(f"four devices expected and found in {found:.2f} s = {found / window:.2f}× the search window "
                  f"(target < 5 s); CPU {found_cpu:.2f} s (this process: the devices and discovery)")
            unplug: list[float] = []
            plug: list[float] = []
            cpus: dict[str, list[float]] = {"unplug": [], "plug": []}
            for _ in range(rounds):
                for kind, times, action in (("unplug", unplug, sim.unplug), ("plug", plug, sim.plug)):
                    t, c = time.perf_counter(), time.process_time()
                    await action("gripper")
                    await until(live, kind, "gripper")
                    offered = service.capabilities(live.cell).commands()
                    assert ("pick" in offered) == (kind == "plug")
                    times.append(time.perf_counter() - t)
                    cpus[kind].append(time.process_time() - c)
    for kind, times in (("unplug", unplug), ("plug", plug)):
        print(f"{kind} gripper → offered commands re-inferred: median {1000 * statistics.median(times):.0f} ms, "
              f"max {1000 * max(times):.0f} ms over {rounds} rounds (target < 1 s); CPU median "
              f"{1000 * statistics.median(cpus[kind]):.0f} ms")


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=20)
    asyncio.run(main(parser.parse_args().rounds))
