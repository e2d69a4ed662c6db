"""Two hosts on a virtual Ethernet link, each in a network namespace of its own, made by a test and deleted after.

``with linked_hosts() as (devices, controller):`` makes two namespaces, a veth pair between them with an address
from a private test range on each end, both links and loopback up and a multicast route on the link, then deletes
both namespaces however the block ends. Only the two addresses made here are used; the machine's own interfaces
are never touched (the veth ends are created inside the namespaces). Where namespaces cannot be made (not root,
no ``ip``), the test is skipped, saying why.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import uuid
from collections.abc import Iterator
from dataclasses import dataclass

import pytest

SUBNET = "10.213.26"
"""The private test range of the link (a /24): the devices' host is .1, the controller's .2."""


@dataclass(frozen=True)
class Host:
    """One end of the link: its namespace, the name of its interface and that interface's address."""

    namespace: str
    interface: str
    address: str

    def command(self, *args: str) -> list[str]:
        """``args`` run in this host's namespace."""
        return [_ip(), "netns", "exec", self.namespace, *args]

    def pnp(self, *args: str) -> list[str]:
        """``python -m plugnproduce args`` run in this host's namespace."""
        return self.command(sys.executable, "-m", "plugnproduce", *args)


def _ip() -> str:
    found = shutil.which("ip") or next((p for p in ("/usr/sbin/ip", "/sbin/ip") if os.access(p, os.X_OK)), None)
    if found is None:
        pytest.skip("network namespaces cannot be made here: no 'ip' command (install iproute2)")
    return found


def _run(*args: str) -> None:
    subprocess.run([_ip(), *args], check=True, capture_output=True, text=True, timeout=60)


def _delete(namespace: str) -> None:
    subprocess.run([_ip(), "netns", "delete", namespace], capture_output=True, timeout=60)


@contextlib.contextmanager
def linked_hosts() -> Iterator[tuple[Host, Host]]:
    """The devices' host and the controller's, linked; both namespaces deleted afterwards, even on failure."""
    if os.geteuid() != 0:
        pytest.skip("network namespaces cannot be made here: creating them needs root (CI runs as root)")
    tag = uuid.uuid4().hex[:8]
    devices = Host(f"pnp-devices-{tag}", "pnp0", f"{SUBNET}.1")
    controller = Host(f"pnp-controller-{tag}", "pnp1", f"{SUBNET}.2")
    try:
        _run("netns", "add", devices.namespace)
    except subprocess.CalledProcessError as exc:
        pytest.skip(f"network namespaces cannot be made here: 'ip netns add' says {exc.stderr.strip()}")
    try:
        _run("netns", "add", controller.namespace)
        _run("link", "add", devices.interface, "netns", devices.namespace, "type", "veth",
             "peer", "name", controller.interface, "netns", controller.namespace)
        for host in (devices, controller):
            _run("-n", host.namespace, "addr", "add", f"{host.address}/24", "dev", host.interface)
            _run("-n", host.namespace, "link", "set", "lo", "up")
            _run("-n", host.namespace, "link", "set", host.interface, "up")
            _run("-n", host.namespace, "route", "add", "224.0.0.0/4", "dev", host.interface)
        yield devices, controller
    finally:
        _delete(controller.namespace)
        _delete(devices.namespace)
