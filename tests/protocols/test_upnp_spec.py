"""The pure parts of the UPnP side: chart events to service, spec checks, the trust rule."""

from __future__ import annotations

import uuid

import pytest

from plugnproduce.errors import DescriptionError, ProtocolError
from plugnproduce.protocols.upnp import (
    STATE_ACTION,
    ActionSpec,
    ArgumentSpec,
    DeviceFiles,
    ServiceSpec,
    UntrustedUrlError,
    VariableSpec,
    device_type_for,
    payload_of,
    report_text,
    reported_of,
    service_spec_from_chart_events,
    udn_for,
    with_state_query,
)
from plugnproduce.protocols.upnp.boundary import check_trusted, resolve_trusted


def test_chart_requests_become_actions_with_their_parameters() -> None:
    spec = service_spec_from_chart_events({"MoveTo": ["Pose", "Speed"], "Home": []}, [])
    assert [a.name for a in spec.actions] == ["Home", "MoveTo"]
    assert spec.action("MoveTo").input_names == ("Pose", "Speed")
    assert spec.action("MoveTo").inputs[0].data_type == "string"
    assert [a.name for a in spec.action("Home").outputs] == ["Result"]


def test_chart_events_become_counting_evented_variables() -> None:
    spec = service_spec_from_chart_events({}, ["arrived", "homed", "arrived"])
    assert spec.variables == (
        VariableSpec("arrived", "ui4", default="0"),
        VariableSpec("homed", "ui4", default="0"),
    )


def test_repeated_request_parameters_appear_once() -> None:
    spec = service_spec_from_chart_events({"Close": ["GripForce", "GripForce"]}, [])
    assert spec.action("Close").input_names == ("GripForce",)


def test_argument_types_override_the_string_default() -> None:
    spec = service_spec_from_chart_events({"Close": ["GripForce"]}, [], argument_types={"GripForce": "r8"})
    assert spec.action("Close").inputs[0].data_type == "r8"


@pytest.mark.parametrize(
    ("build", "expected"),
    [
        (lambda: service_spec_from_chart_events({}, ["gripper-closed"]), "'gripper-closed' cannot be a UPnP name"),
        (lambda: ArgumentSpec("x", "float64"), "expected one of the UPnP types"),
        (lambda: VariableSpec("Mode", allowed_values=("a", "b"), default="c"), "default 'c' is not one of"),
        (lambda: VariableSpec("A_ARG_TYPE_x"), "prefix A_ARG_TYPE_ is reserved"),
        (lambda: ArgumentSpec("n", "i4", allowed_values=("one",)), "allowed value 'one' is not a i4"),
        (lambda: ActionSpec("Go", (ArgumentSpec("Result"),)), "names argument(s) Result more than once"),
        (lambda: ServiceSpec((ActionSpec("Go"), ActionSpec("Go"))), "action name(s) Go given more than once"),
        (lambda: DeviceFiles("../x.ttl", "", "x.scxml", ""), "'../x.ttl' cannot be served"),
    ],
)
def test_unusable_specs_are_refused_with_the_reason(build, expected: str) -> None:
    with pytest.raises(DescriptionError) as info:
        build()
    assert expected in str(info.value)


def test_device_type_and_udn() -> None:
    assert device_type_for("ParallelGripper") == "urn:plugnproduce-org:device:ParallelGripper:1"
    # docs/upnp.md: `uuid:` + a name-based UUID (v5) of the device's IRI, so a restarted device keeps its UDN
    for device in ("gripper", "robot"):
        named = uuid.uuid5(uuid.NAMESPACE_URL, f"http://plugnproduce.org/devices/{device}")
        assert udn_for(device) == f"uuid:{named}"
        assert uuid.UUID(udn_for(device).removeprefix("uuid:")).version == 5
    assert udn_for("gripper") != udn_for("robot")


def test_url_on_the_discovered_host_is_trusted() -> None:
    url = "http://127.0.0.1:4711/pnp/gripper.scxml"
    assert check_trusted(url, "127.0.0.1", "chart") == url
    assert resolve_trusted("http://127.0.0.1:4711/device.xml", "/pnp/gripper.scxml", "127.0.0.1", "chart") == url


@pytest.mark.parametrize(
    "reference",
    [
        "http://127.0.0.2:4711/pnp/gripper.scxml",
        "http://localhost:4711/pnp/gripper.scxml",
        "//10.0.0.1/pnp/gripper.scxml",
        "file:///etc/passwd",
        "https://127.0.0.1/pnp/gripper.scxml",
    ],
)
def test_file_url_elsewhere_is_refused(reference: str) -> None:
    with pytest.raises(UntrustedUrlError) as info:
        resolve_trusted("http://127.0.0.1:4711/device.xml", reference, "127.0.0.1", "pnp:chartURL of gripper")
    assert isinstance(info.value, ProtocolError)
    assert "pnp:chartURL of gripper" in str(info.value)
    assert "refused" in str(info.value)


@pytest.mark.parametrize(("text", "why"), [
    ("[NaN, 0, 0, 0, 180, 0]", "is not a JSON value"),
    ("[" * 2000 + "]" * 2000, "is not a JSON value"),  # deeper than the decoder recurses
    ("[0.4, 0.0", "is not a JSON value"),
    ("[" + "0, " * 2000 + "0]", "is no text of at most 4096 characters"),
])
def test_a_reported_value_that_is_no_bounded_json_value_is_refused_naming_the_device(text: str, why: str) -> None:
    with pytest.raises(ValueError, match=f"^device arm: GetDeviceState: TargetPose {why}"):
        reported_of({"State": "home", "TargetPose": text}, ["TargetPose"], "device arm: GetDeviceState")


def test_the_reported_values_of_a_state_query_are_read_from_json_and_a_missing_one_is_left_out() -> None:
    results = {"State": "at_pose", "TargetPose": report_text([0.35, 0.15, 0.22, 0, 180, 45])}
    assert reported_of(results, ["TargetPose", "Force"], "device arm") == {"TargetPose": [0.35, 0.15, 0.22, 0, 180, 45]}
    spec = with_state_query(ServiceSpec(), reports=["TargetPose"])
    assert [a.name for a in spec.action(STATE_ACTION).outputs] == ["State", "TargetPose"]


def test_an_event_value_nested_deeper_than_the_json_decoder_recurses_is_kept_as_its_text() -> None:
    """A device's GENA notification is read in the controller's event callback: a value it cannot decode stays
    the text it was (the run's contract checks then refuse it), never an exception there."""
    deep = "[" * 2000 + "]" * 2000
    values = {"PartLocalized__part_pose": deep, "PartLocalized__outcome": '"PartFound"'}
    assert payload_of(values, "PartLocalized") == {"part_pose": deep, "outcome": "PartFound"}
