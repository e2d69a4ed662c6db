"""What the controller's SSDP search and announcement listener share: the messages' UDN and source, and a guarded
socket.

Everything found carries ``source_host``, the address the SSDP message came from: the only host the device is
trusted for (see :mod:`plugnproduce.protocols.upnp.boundary`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from aiohttp.http_exceptions import BadHttpMessage
from async_upnp_client.advertisement import SsdpAdvertisementListener
from async_upnp_client.search import SsdpSearchListener
from async_upnp_client.utils import CaseInsensitiveDict

from plugnproduce.protocols.upnp.boundary import hear_only_the_interface

_LOGGER = logging.getLogger(__name__)

MAX_CANDIDATES = 8
"""Most places kept per UDN (an announcer cycling through description URLs costs no more)."""

@dataclass(frozen=True)
class Advertisement:
    """A device announced itself (``alive``) or its leaving (``byebye``)."""

    udn: str
    alive: bool
    location: str | None
    source_host: str


def guard_listener(listener: SsdpSearchListener | SsdpAdvertisementListener) -> None:
    """Have ``listener``'s socket drop every datagram async-upnp-client cannot parse, and hear only its interface.

    The library ignores a datagram with an invalid header line but lets other malformed ones
    (a duplicate header: aiohttp's ``BadHttpMessage``; a header that is not UTF-8: a
    ``UnicodeDecodeError``) out of its protocol, where asyncio logs a traceback for each: any peer
    could flood the log so.
    """
    transport = getattr(listener, "_transport", None)
    if transport is None:
        return
    hear_only_the_interface(transport)
    protocol = transport.get_protocol()
    received = protocol.datagram_received

    def guarded(data: bytes, addr: tuple[str, int]) -> None:
        try:
            received(data, addr)
        except (BadHttpMessage, ValueError):
            _LOGGER.debug("ignoring a malformed SSDP datagram from %s", addr[0])

    protocol.datagram_received = guarded


def headers_udn(headers: CaseInsensitiveDict) -> tuple[str, str | None, str] | None:
    """The UDN, description URL and source host of an SSDP message; None (logged) without UDN or source."""
    udn, location, host = headers.get_lower("_udn"), headers.get_lower("location"), headers.get_lower("_host")
    if not udn or not host:
        _LOGGER.debug("ignoring SSDP message without USN or source: %s", headers.as_dict())
        return None
    return str(udn), str(location) if location else None, str(host)
