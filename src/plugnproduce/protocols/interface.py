"""The network interface the devices are spoken to on: loopback unless ``--interface`` or ``PNP_INTERFACE`` names one.

Every protocol runs on the one address chosen here: SSDP sends its multicast out of it and joins
the group on it, the simulated devices' UPnP (HTTP) and XIRP (TCP) servers listen on it, and so
does any protocol added later (an OPC UA server binds its endpoint to it, a client searches from it).
The choice is made once, at the command line, into an :class:`~plugnproduce.protocols.upnp.SsdpNetwork`
whose ``interface`` is this address; nothing below the command line reads the environment for it.

An interface is named by its name (``eth0``: its first IPv4 address) or by one of this machine's
IPv4 addresses. Interfaces are listed with ifaddr.
"""

from __future__ import annotations

import ipaddress
import os

import ifaddr

from plugnproduce.errors import ProtocolError, excerpt

INTERFACE_VARIABLE = "PNP_INTERFACE"
"""Environment variable naming the interface when no ``--interface`` is given."""

LOOPBACK_ADDRESS = "127.0.0.1"
"""The default: everything stays on this machine."""


class UnknownInterface(ProtocolError):
    """No interface of this machine has that name or IPv4 address."""


def _ipv4_addresses() -> dict[str, list[str]]:
    """Each interface's IPv4 addresses, by interface name."""
    return {adapter.name: [str(ip.ip) for ip in adapter.ips if ip.is_IPv4] for adapter in ifaddr.get_adapters()}


def _known(interfaces: dict[str, list[str]]) -> str:
    return "; ".join(f"{name} {', '.join(addresses) or '(no IPv4 address)'}"
                     for name, addresses in sorted(interfaces.items())) or "none"


def interface_address(name_or_address: str, what: str = "--interface") -> str:
    """The IPv4 address of the interface named ``name_or_address``, or that address if it is one of this machine's.

    Raises :class:`UnknownInterface` (one line, listing the interfaces there are) for anything else.
    """
    text = name_or_address.strip()
    interfaces = _ipv4_addresses()
    try:
        address = ipaddress.ip_address(text)
    except ValueError:
        address = None
    if address is not None:
        if address.version != 4:
            raise UnknownInterface(f"{what} {excerpt(text)}: an IPv6 address; give an IPv4 address or an interface "
                                   f"name (interfaces: {_known(interfaces)})")
        if any(str(address) in addresses for addresses in interfaces.values()):
            return str(address)
        raise UnknownInterface(f"{what} {excerpt(text)}: no interface of this machine has that address "
                               f"(interfaces: {_known(interfaces)})")
    if text not in interfaces:
        raise UnknownInterface(f"{what} {excerpt(text)!r}: no such interface (interfaces: {_known(interfaces)})")
    if not interfaces[text]:
        raise UnknownInterface(f"{what} {excerpt(text)}: the interface has no IPv4 address")
    return interfaces[text][0]


def chosen_address(option: str | None = None) -> str:
    """The address the command line chose: ``--interface`` (``option``), else ``PNP_INTERFACE``, else loopback."""
    if option:
        return interface_address(option)
    from_environment = os.environ.get(INTERFACE_VARIABLE, "").strip()
    if from_environment:
        return interface_address(from_environment, INTERFACE_VARIABLE)
    return LOOPBACK_ADDRESS
