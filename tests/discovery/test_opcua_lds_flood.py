"""The controller's own Local Discovery Server is a device-facing edge: anyone on the network may register with
it. However many servers register, and however large their registrations, its FindServers answer stays within
the limits of the controller that asks it, so a flood cannot make the controller refuse its own LDS; the
registrations beyond the limits are refused, and an honest device registered first is found all the same."""

from __future__ import annotations

from collections.abc import AsyncIterator

import pytest
from asyncua import Client, ua

from plugnproduce.protocols.opcua.discovery import (
    MAX_REGISTERED,
    MAX_TEXT,
    MAX_URL,
    MAX_URLS,
    LocalDiscoveryServer,
    find_servers,
)
from tests.lines import WAIT


@pytest.fixture
async def lds() -> AsyncIterator[str]:
    async with LocalDiscoveryServer(port=0) as server:
        assert server.endpoint is not None
        yield server.endpoint


def _registration(name: str, *, urls: int = MAX_URLS, url: int = MAX_URL, text: int = MAX_TEXT) -> ua.RegisteredServer:
    """A registration as large as the limits allow (or larger, where asked)."""
    return ua.RegisteredServer(
        ServerUri=f"urn:plugnproduce:device:{name}", ProductUri="p" * text, GatewayServerUri="g" * text,
        ServerNames=[ua.LocalizedText("n" * text, "en")], ServerType=ua.ApplicationType.Server, IsOnline=True,
        DiscoveryUrls=[(f"opc.tcp://127.0.0.1:4840/{name}/{k}/" + "u" * url)[:url] for k in range(urls)])


async def test_a_flood_of_the_largest_registrations_stays_within_the_controllers_limits(lds: str) -> None:
    async with Client(lds, timeout=WAIT) as flooder:
        await flooder.uaclient.register_server(_registration("honest", urls=1, url=40, text=40))
        for n in range(MAX_REGISTERED - 1):
            await flooder.uaclient.register_server(_registration(f"flood{n}"))
        with pytest.raises(ua.UaStatusCodeError, match="BadResourceUnavailable"):
            await flooder.uaclient.register_server(_registration("one-more"))
        await flooder.uaclient.register_server(_registration("flood0"))  # a renewal is taken when full
    listed = dict(await find_servers(lds, WAIT))  # the whole answer, read within the controller's limits
    assert len(listed) == MAX_REGISTERED
    assert listed["honest"] == "opc.tcp://127.0.0.1:4840/honest/0/uuuuuu"
    assert "one-more" not in "".join(listed)


@pytest.mark.parametrize("too_large", [{"urls": MAX_URLS + 1}, {"url": MAX_URL + 1}, {"text": MAX_TEXT + 1},
                                       {"urls": 0}])
async def test_a_registration_beyond_the_limits_is_refused(lds: str, too_large: dict[str, int]) -> None:
    async with Client(lds, timeout=WAIT) as client:
        with pytest.raises(ua.UaStatusCodeError, match="BadInvalidArgument"):
            await client.uaclient.register_server(_registration("big", **too_large))
    assert await find_servers(lds, WAIT) == []
