"""XIRP frames and what a UPnP device answers, mutated from valid ones.

An XIRP payload decodes or is refused with ``MessageError``; what a device serves (its Turtle
and chart) is read by the live cell's own function or refused with a ``DescriptionError`` or
``ProtocolError``; a URL a device names is resolved only to the host it was found at. A device's
UPnP root description and SCPD are read or refused with a ``ProtocolError``; an SSDP datagram is
reported with a UDN and its source, or ignored, and a description URL it names off its sender's
host is refused in one line.
"""

from __future__ import annotations

import random

from fuzzing import (
    REFERENCES,
    Workspace,
    mutate,
    run_reference,
    run_served,
    run_ssdp,
    run_upnp_description,
    run_xirp,
    seeds,
    ssdp_seeds,
    upnp_seeds,
    xirp_seeds,
)
from hypothesis import given, settings
from hypothesis import strategies as st

FUZZ = settings.get_profile("fuzz")
XIRP = xirp_seeds()


@settings(FUZZ, max_examples=200)
@given(seed=st.sampled_from(XIRP), rng=st.randoms(use_true_random=False))
def test_mutated_xirp_frame_decodes_or_is_refused_in_one_line(seed: bytes, rng: random.Random) -> None:
    assert run_xirp(mutate(seed, rng)) in ("accepted", "refused")


@settings(FUZZ, max_examples=100)
@given(data=st.binary(max_size=400))
def test_any_bytes_decode_or_are_refused_in_one_line(data: bytes) -> None:
    assert run_xirp(data) in ("accepted", "refused")


DEVICES = [(r.split("/")[1].removesuffix(".ttl"), d) for r, d in seeds("turtle") if r.startswith("devices/")]
CHARTS = dict((r.split("/")[1].removesuffix(".scxml"), d) for r, d in seeds("chart") if r.startswith("devices/"))


@FUZZ
@given(device=st.sampled_from(DEVICES), rng=st.randoms(use_true_random=False), which=st.sampled_from(["ttl", "scxml"]),
       location=st.sampled_from(["http://127.0.0.1:8000/dev/description.xml", "http://localhost:1/d.xml",
                                 "http://[::1]:80/x.xml"]))
def test_what_a_device_serves_is_read_or_refused_in_one_line(workspace: Workspace, device: tuple[str, bytes],
                                                             rng: random.Random, which: str, location: str) -> None:
    name, description = device
    chart = CHARTS[name]
    if which == "ttl":
        description = mutate(description, rng)
    else:
        chart = mutate(chart, rng)
    assert run_served(workspace, name, description, chart, location) in ("accepted", "refused")


@FUZZ
@given(reference=st.sampled_from(REFERENCES) | st.text(max_size=60))
def test_a_url_a_device_names_is_resolved_only_on_its_host(reference: str) -> None:
    assert run_reference("http://127.0.0.1:8000/dev/description.xml", reference) in ("accepted", "refused")


ROOT, SCPD = upnp_seeds()


@FUZZ
@given(rng=st.randoms(use_true_random=False), which=st.sampled_from(["root", "scpd", "both"]))
def test_a_mutated_upnp_description_is_read_or_refused_in_one_line(rng: random.Random, which: str) -> None:
    root = mutate(ROOT, rng) if which in ("root", "both") else ROOT
    scpd = mutate(SCPD, rng) if which in ("scpd", "both") else SCPD
    assert run_upnp_description(root, scpd) in ("accepted", "refused")


@settings(FUZZ, max_examples=100)
@given(seed=st.sampled_from(ssdp_seeds()), rng=st.randoms(use_true_random=False))
def test_a_mutated_ssdp_datagram_is_reported_or_ignored(seed: bytes, rng: random.Random) -> None:
    assert run_ssdp(mutate(seed, rng)) in ("accepted", "refused")


HEADER_NAMES = ["HOST", "USN", "NT", "NTS", "ST", "LOCATION", "CACHE-CONTROL", "SERVER", "EXT", "MAN", "BOOTID.UPNP.ORG"]
HEADER_VALUES = st.sampled_from(["ssdp:alive", "ssdp:byebye", "ssdp:update", "uuid:x::upnp:rootdevice", "uuid:",
                                 "::", "http://127.0.0.1:1/d.xml", "http://10.0.0.1/d.xml", "file:///etc/passwd",
                                 "/etc/passwd", "http://[zz/x", "max-age=-1", ""]) | st.text(max_size=80)


@settings(FUZZ, max_examples=100)
@given(start=st.sampled_from(["NOTIFY * HTTP/1.1", "HTTP/1.1 200 OK", "M-SEARCH * HTTP/1.1", "GET / HTTP/1.0"]),
       headers=st.lists(st.tuples(st.sampled_from(HEADER_NAMES) | st.text(max_size=20), HEADER_VALUES), max_size=12))
def test_ssdp_headers_of_any_content_are_reported_or_ignored(start: str, headers: list[tuple[str, str]]) -> None:
    lines = [start, *(f"{name}: {value}" for name, value in headers)]
    data = ("\r\n".join(lines) + "\r\n\r\n").encode("utf-8", "surrogatepass")
    assert run_ssdp(data) in ("accepted", "refused")
