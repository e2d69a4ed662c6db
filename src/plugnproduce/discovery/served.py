"""The trust rules for the description a discovered device serves itself (over UPnP's HTTP or OPC UA's
``Description`` object): read from memory as any description, its chart the one it serves, its endpoint on the
host it was found at, reached there and never by name. Anything else is refused, naming where it was served.
"""

from __future__ import annotations

import ipaddress
import re
from dataclasses import replace
from pathlib import Path
from urllib.parse import urlparse

from rdflib.term import Node

from plugnproduce.description.loader import device_from, file_of, parse_description
from plugnproduce.description.model import DeviceDescription
from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP
from plugnproduce.protocols.opcua import spec as opcua_spec
from plugnproduce.protocols.upnp import FoundDevice, RemoteFiles, UntrustedUrlError
from plugnproduce.protocols.xirp import format_endpoint, parse_endpoint

SERVED = Path("/served")
"""Where a discovered device's files are said to be: a name for messages and relative IRIs, never a folder
on disk (a device's chart is only the chart it serves)."""


def _safe_name(name: str) -> str:
    """A file name that stays inside its folder, from anything a device sends."""
    cleaned = re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip(".")
    return cleaned[:100] or "unnamed"


def _is_served_chart(named: Node, chart: Path) -> bool:
    """Whether a chart a description names is the chart the device served (a NUL, even %00, names no file)."""
    path = file_of(named)
    return "\0" not in str(path) and path.resolve() == chart.resolve()


def read_served(files: RemoteFiles, found: FoundDevice, taxonomy: Taxonomy) -> DeviceDescription:
    """Read the description and chart a device served (fetched already) as any description, from memory.

    The chart must be the one the device serves and an XIRP endpoint must be on the host the
    device was found at; anything else is refused (:class:`DescriptionError`, :class:`ProtocolError`),
    naming the URL the device served the file at.
    """
    folder = SERVED / _safe_name(found.udn)  # names the files for messages and relative IRIs; nothing is written
    ttl = folder / _safe_name(Path(urlparse(files.description_url).path).name or "description.ttl")
    chart = folder / _safe_name(Path(urlparse(files.chart_url).path).name or "chart.scxml")
    try:
        loaded = parse_description(files.description.encode("utf-8"), ttl)
        for named in loaded.graph.objects(None, PNP.stateChart):
            if not _is_served_chart(named, chart):
                raise DescriptionError(f"device {found.udn} names its chart <{excerpt(str(named))}>; expected "
                                       f"the chart it serves ({chart.name})", ttl)
        device = device_from(loaded, taxonomy, charts={chart: files.chart.encode("utf-8")})
    except DescriptionError as exc:  # say where the device serves the file, not the name it was read under
        served = {str(ttl): files.description_url, str(chart): files.chart_url}
        raise DescriptionError(exc.message.replace(str(folder), ""), served.get(exc.file or "", found.location),
                               exc.line) from exc
    if device.protocol == "upnp":  # reached where it was found, whatever its Turtle says
        return replace(device, endpoint=found.location)
    host = urlparse(found.location).hostname  # None: found at no host, so no endpoint is on its host
    named_host, port, path = _endpoint_parts(device.protocol, device.endpoint)
    if host is None or (named_host != host and not (named_host.lower() == "localhost" and _is_loopback(host))):
        raise UntrustedUrlError(f"device {excerpt(device.id)} found at {host or excerpt(found.location)} "
                                f"names {_NAMES[device.protocol]} endpoint {excerpt(device.endpoint)} on another "
                                "host; refused")
    # reached where it was found, never by name
    if device.protocol == "opcua":
        return replace(device, endpoint=opcua_spec.format_endpoint(host, port, path))
    return replace(device, endpoint=format_endpoint(host, port))


_NAMES = {"xirp": "XIRP", "opcua": "OPC UA"}


def _endpoint_parts(protocol: str, endpoint: str) -> tuple[str, int, str]:
    """Host, port and path of an XIRP or OPC UA endpoint (a ProtocolError for any other)."""
    if protocol == "opcua":
        return opcua_spec.parse_endpoint(endpoint)
    host, port = parse_endpoint(endpoint)
    return host, port, ""


def _is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback address (``localhost`` always names this machine)."""
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
