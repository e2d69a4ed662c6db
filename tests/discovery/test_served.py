"""What a discovered device may name, read from the files it served (no network, no disk).

A device's chart is only the chart it serves: a description naming a local file, another
host or a path elsewhere is refused naming the URL the device served it at, and nothing local
is read. An XIRP device's endpoint must be on the host it was found at; a UPnP device is
reached where it was found, whatever its Turtle says. Whatever a device calls itself, the
names it is read under stay inside its own folder.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.discovery.served import read_served
from plugnproduce.errors import DescriptionError
from plugnproduce.protocols.upnp import FoundDevice, RemoteFiles, UntrustedUrlError
from plugnproduce.resources import descriptions_path

DEVICES = descriptions_path() / "devices"
BASE = "http://127.0.0.1:8000/files"


def served(device: str, *, turtle: tuple[str, str] | None = None, udn: str = "uuid:dev-1",
           chart_url: str | None = None, location: str = f"{BASE}/device.xml") -> RemoteFiles | tuple:
    text = (DEVICES / f"{device}.ttl").read_text(encoding="utf-8")
    if turtle is not None:
        assert turtle[0] in text
        text = text.replace(*turtle)
    files = RemoteFiles(f"{BASE}/{device}.ttl", text, chart_url or f"{BASE}/{device}.scxml",
                        (DEVICES / f"{device}.scxml").read_text(encoding="utf-8"))
    found = FoundDevice(udn, location, "urn:schemas-plugnproduce-org:device:Device:1", device, "127.0.0.1")
    return files, found


def read(device: str, **changes: object):  # type: ignore[no-untyped-def]
    files, found = served(device, **changes)  # type: ignore[arg-type]
    return read_served(files, found, service.knowledge().taxonomy)


def test_an_honest_xirp_device_is_read_with_its_endpoint() -> None:
    device = read("gripper")
    assert device.id == "gripper" and device.endpoint == "xirp://127.0.0.1:0"


def test_a_upnp_device_is_reached_where_it_was_found_whatever_its_turtle_says() -> None:
    device = read("camera", location="http://127.0.0.1:8123/camera.xml")
    assert device.protocol == "upnp" and device.endpoint == "http://127.0.0.1:8123/camera.xml"


@pytest.mark.parametrize("chart", ["file:///etc/passwd", "http://10.0.0.9/gripper.scxml", "/etc/passwd",
                                   "http://127.0.0.1:8000/files/other.scxml", "gripper%00.scxml"])
def test_a_device_naming_any_chart_but_the_one_it_serves_is_refused(chart: str) -> None:
    with pytest.raises(DescriptionError) as caught:
        read("gripper", turtle=("<gripper.scxml>", f"<{chart}>"))
    message = str(caught.value)
    assert message.startswith(f"{BASE}/gripper.ttl:"), message
    assert "expected the chart it serves (gripper.scxml)" in message and "root:" not in message
    assert "/served" not in message


def test_issue_15_a_percent_encoded_nul_in_the_chart_name_is_a_refusal_not_a_crash() -> None:
    """``<gripper%00.scxml>`` decodes to a path with a NUL, which ``Path.resolve`` cannot take (ValueError)."""
    with pytest.raises(DescriptionError, match=r"names its chart <file:///gripper%00.scxml>; expected the chart it serves"):
        read("gripper", turtle=("<gripper.scxml>", "<gripper%00.scxml>"))


@pytest.mark.parametrize("endpoint", ["xirp://10.0.0.9:7000", "xirp://127.0.0.2:7000", "xirp://localhost.example:7000"])
def test_an_xirp_endpoint_on_another_host_is_refused(endpoint: str) -> None:
    with pytest.raises(UntrustedUrlError, match="found at 127.0.0.1 names XIRP endpoint .* on another host"):
        read("gripper", turtle=('"xirp://127.0.0.1:0"', f'"{endpoint}"'))


@pytest.mark.parametrize("endpoint", ["xirp://localhost:7000", "xirp://LocalHost:7000"])
def test_issue_15_a_device_found_on_loopback_may_name_its_endpoint_localhost(endpoint: str) -> None:
    """``localhost`` always names this machine; the device is then reached at the address it was found at."""
    assert read("gripper", turtle=('"xirp://127.0.0.1:0"', f'"{endpoint}"')).endpoint == "xirp://127.0.0.1:7000"


def test_a_device_found_elsewhere_may_not_name_its_endpoint_localhost() -> None:
    files, found = served("gripper", turtle=('"xirp://127.0.0.1:0"', '"xirp://localhost:7000"'),
                          location="http://10.0.0.9:8000/files/device.xml")
    with pytest.raises(UntrustedUrlError, match="found at 10.0.0.9 names XIRP endpoint .* on another host"):
        read_served(files, found, service.knowledge().taxonomy)


@pytest.mark.parametrize("location", ["http:///files/device.xml", "file:///files/device.xml"])
def test_a_device_found_at_a_location_without_a_host_may_name_no_xirp_endpoint(location: str) -> None:
    files, found = served("gripper", location=location)
    with pytest.raises(UntrustedUrlError, match=f"found at {location} names XIRP endpoint .* on another host"):
        read_served(files, found, service.knowledge().taxonomy)


@pytest.mark.parametrize("udn", ["uuid:../../etc", "uuid:" + "a" * 3000, "..", "uuid:dev/1 ?#"])
def test_whatever_a_device_calls_itself_its_own_chart_is_found(udn: str) -> None:
    assert read("gripper", udn=udn).id == "gripper"


def test_a_description_served_without_a_file_name_is_still_read() -> None:
    files, found = served("gripper")
    files = RemoteFiles(f"{BASE}/", files.description, files.chart_url, files.chart)  # type: ignore[union-attr]
    assert read_served(files, found, service.knowledge().taxonomy).id == "gripper"


def test_an_error_in_the_served_chart_names_the_chart_url() -> None:
    files, found = served("gripper")
    broken = RemoteFiles(files.description_url, files.description, files.chart_url, "<scxml")  # type: ignore[union-attr]
    with pytest.raises(DescriptionError) as caught:
        read_served(broken, found, service.knowledge().taxonomy)
    assert str(caught.value).startswith(f"{BASE}/gripper.scxml"), str(caught.value)
    assert Path("/served").as_posix() not in str(caught.value)


@pytest.mark.parametrize("name", ["XGripper-2.scxml", "g" * 94 + ".scxml"])
def test_a_chart_served_under_a_plain_name_of_up_to_100_characters_is_matched(name: str) -> None:
    device = read("gripper", turtle=("<gripper.scxml>", f"<{name}>"), chart_url=f"{BASE}/{name}")
    assert device.id == "gripper"


@pytest.mark.parametrize(("name", "shown"), [
    ("g" * 95 + ".scxml", "g" * 95 + ".scxm"),
    (".gripper.scxml", "gripper.scxml"),
    ("grip%20per.scxml", "grip_20per.scxml"),
    ("...", "unnamed"),
])
def test_a_chart_served_under_a_name_that_is_not_a_plain_file_name_is_refused(name: str, shown: str) -> None:
    with pytest.raises(DescriptionError, match=f"expected the chart it serves \\({re.escape(shown)}\\)$"):
        read("gripper", turtle=("<gripper.scxml>", f"<{name}>"), chart_url=f"{BASE}/{name}")


def test_a_chart_served_without_a_file_name_is_the_chart_named_chart_scxml() -> None:
    device = read("gripper", turtle=("<gripper.scxml>", "<chart.scxml>"), chart_url="http://127.0.0.1:8000/")
    assert device.id == "gripper"
