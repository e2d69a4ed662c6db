"""``--interface NAME|ADDRESS`` and ``PNP_INTERFACE``: which address the devices are found and spoken to on.

Nothing here sends a packet: the addresses are only resolved (198.51.100.7 is a documentation address that no
interface here has).
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from plugnproduce import service
from plugnproduce.protocols.interface import INTERFACE_VARIABLE, UnknownInterface, chosen_address, interface_address
from plugnproduce.protocols.upnp import SsdpNetwork, network_from_env, private_network

CELL = str(service.builtin("cells", "bin-picking.yaml"))
TASK = str(service.builtin("tasks", "bin-picking.yaml"))
ELSEWHERE = "198.51.100.7"


def test_an_interface_name_is_its_ipv4_address() -> None:
    assert interface_address("lo") == "127.0.0.1"


def test_an_address_of_this_machine_is_itself() -> None:
    assert interface_address(" 127.0.0.1 ") == "127.0.0.1"


def test_an_unknown_name_is_refused_naming_the_interfaces_there_are() -> None:
    with pytest.raises(UnknownInterface, match=r"--interface 'no-such0': no such interface \(interfaces: .*lo "
                                               r"127\.0\.0\.1"):
        interface_address("no-such0")


def test_an_address_no_interface_has_is_refused() -> None:
    with pytest.raises(UnknownInterface, match=f"{ELSEWHERE}: no interface of this machine has that address"):
        interface_address(ELSEWHERE)


def test_an_ipv6_address_is_refused_as_such() -> None:
    with pytest.raises(UnknownInterface, match="::1: an IPv6 address; give an IPv4 address or an interface name"):
        interface_address("::1")


def test_the_option_wins_over_the_environment_and_loopback_is_the_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(INTERFACE_VARIABLE, raising=False)
    assert chosen_address() == "127.0.0.1"
    monkeypatch.setenv(INTERFACE_VARIABLE, "no-such0")
    with pytest.raises(UnknownInterface, match="PNP_INTERFACE 'no-such0'"):
        chosen_address()
    assert chosen_address("lo") == "127.0.0.1"
    monkeypatch.setenv(INTERFACE_VARIABLE, "lo")
    assert chosen_address() == "127.0.0.1"


def test_the_ssdp_network_is_on_the_chosen_address_and_port(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNP_SSDP_PORT", "41900")
    assert network_from_env("lo") == SsdpNetwork(interface="127.0.0.1", port=41900)
    private = private_network("127.0.0.1")
    assert private.interface == "127.0.0.1" and private.port != 1900


def _pnp(*args: str, **env: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True,
                          env={**os.environ, **env}, timeout=300)


@pytest.mark.parametrize("args", [
    ("discover", "--interface", "no-such0"),
    ("sim", "up", CELL, "--interface", "no-such0"),
    ("run", TASK, "--cell", CELL, "--interface", "no-such0"),
    ("check", TASK, "--cell", CELL, "--live", "--interface", "no-such0"),
    ("repair", TASK, "--cell", CELL, "--live", "--interface", "no-such0"),
    ("serve", "--interface", "no-such0"),
])
def test_an_unknown_interface_is_one_line_and_exit_2(args: tuple[str, ...]) -> None:
    result = _pnp(*args)
    assert result.returncode == 2, result.stderr
    assert result.stderr.splitlines() == [result.stderr.strip()], result.stderr
    assert "--interface 'no-such0': no such interface" in result.stderr
    assert "Traceback" not in result.stderr and result.stdout == ""


def test_an_unknown_interface_in_the_environment_names_the_variable() -> None:
    result = _pnp("sim", "up", CELL, PNP_INTERFACE=ELSEWHERE)
    assert result.returncode == 2
    assert result.stderr.strip().startswith(f"error: PNP_INTERFACE {ELSEWHERE}: no interface of this machine")


def test_interface_without_live_is_refused_where_nothing_is_found() -> None:
    result = _pnp("check", TASK, "--cell", CELL, "--interface", "lo")
    assert result.returncode == 2
    assert result.stderr.strip() == "--interface works with --live: it is where the cell's devices are found"
