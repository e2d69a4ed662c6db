"""Discovery without configuration over OPC UA: the devices registered with a Local Discovery Server.

``FindServers`` on the LDS lists the devices' servers; each is read beside the others, within its own time
budget: its own description (Turtle and chart, the String variables of ``ns:Description``, each within the
size limit) is read by the same trust rules as a UPnP device's (:func:`~plugnproduce.discovery.served.read_served`):
the chart must be the one it serves, and the endpoint its Turtle names must be on the host it was found at.
A device that breaks a rule, does not answer or serves nonsense is refused, named with the reason; the others
are found all the same.
"""

from __future__ import annotations

import asyncio
from urllib.parse import urlparse

from plugnproduce.description.model import DeviceDescription
from plugnproduce.discovery.served import read_served
from plugnproduce.errors import DescriptionError, ProtocolError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.protocols.opcua.spec import application_uri_for
from plugnproduce.protocols.upnp import FoundDevice, Refusal, RemoteFiles


async def discover_on_lds(lds: str, taxonomy: Taxonomy, timeout: float
                          ) -> tuple[list[DeviceDescription], list[Refusal]]:
    """The devices registered with the LDS at ``lds``, read within ``timeout`` each, and those refused."""
    from plugnproduce.protocols.opcua.discovery import find_servers  # asyncua loads only when asked

    servers = await find_servers(lds, timeout)
    results = await asyncio.gather(*(read_registered(device, url, taxonomy, timeout) for device, url in servers))
    return ([r for r in results if isinstance(r, DeviceDescription)],
            [r for r in results if isinstance(r, Refusal)])


async def registered(lds: str, timeout: float) -> list[tuple[str, str]]:
    """The devices registered with the LDS at ``lds`` now: (device id, discovery URL) each."""
    from plugnproduce.protocols.opcua.discovery import find_servers  # asyncua loads only when asked

    return await find_servers(lds, timeout)


async def read_registered(device: str, url: str, taxonomy: Taxonomy, timeout: float) -> DeviceDescription | Refusal:
    """The device registered as ``device`` at ``url``, read from itself within ``timeout``, or its refusal."""
    from plugnproduce.protocols.opcua import OpcUaDeviceClient

    host = urlparse(url).hostname or ""
    found = FoundDevice(application_uri_for(device), url, "", device, host)
    try:
        client = await OpcUaDeviceClient.connect(url, device, timeout)
        try:
            files = await client.fetch_files(timeout)
        finally:
            await client.close()
        served = RemoteFiles(f"{url}/{files.description_name}", files.description,
                             f"{url}/{files.chart_name}", files.chart)
        described = read_served(served, found, taxonomy)
    except (ProtocolError, DescriptionError) as exc:
        return Refusal(found.udn, url, host, str(exc))
    if described.id != device or described.protocol != "opcua":
        return Refusal(found.udn, url, host, f"registered as device {device} over OPC UA, but describes "
                                             f"{described.id} over {described.protocol}; refused")
    return described
