"""XIRP messages ⇄ bytes, without sockets: round trips, the schema, and what is refused."""

from __future__ import annotations

import re
from datetime import UTC, datetime, timedelta, timezone
from decimal import Decimal

import pytest
from lxml import etree

from plugnproduce.errors import DescriptionError, ProtocolError
from plugnproduce.protocols import upnp, xirp
from plugnproduce.protocols.xirp import (
    MAX_FRAME,
    NAMESPACE,
    Bye,
    DeviceFiles,
    Document,
    ErrorMessage,
    Event,
    Failure,
    Hello,
    Message,
    MessageError,
    Pose,
    Request,
    Response,
    decode,
    documents_of,
    encode,
    encode_frame,
    files_from_documents,
    format_endpoint,
    frame,
    parse_endpoint,
    schema,
)
from plugnproduce.protocols.xirp.codec import frame_length
from plugnproduce.protocols.xirp.decoding import _decode_document
from plugnproduce.protocols.xirp.messages import SCXML, TURTLE

NS = f'xmlns="{NAMESPACE}"'
TIME = datetime(2024, 5, 17, 9, 30, 12, 250000, tzinfo=UTC)
POSE = Pose(0.4, 0.1, 0.2, 0.0, 180.0, -90.5)

MESSAGES: dict[str, Message] = {
    "hello": Hello("gripper", "http://plugnproduce.org/ontology#ParallelGripper", "Parallel gripper PG-70"),
    "hello without description": Hello("robot", "http://plugnproduce.org/ontology#Robot", describe=None),
    "bare request": Request("1", "Open"),
    "request with every type": Request(
        "req-2",
        "MoveTo",
        {"Target": POSE, "Speed": 0.25, "Repeat": 3, "Careful": True, "Note": 'x < y & "z"', "Off": False},
    ),
    "bare response": Response("1"),
    "response with results": Response("7", {"Result": "done", "Force": 39.5}),
    "response with documents": Response(
        "8", documents=(Document("g.ttl", "text/turtle", "@prefix pnp: <x#> .\n"), Document("g.scxml", "a/b", "<s/>"))
    ),
    "failure": Response("9", failure=Failure("not-accepted", "Open is accepted in state closed only")),
    "event": Event("gripper_closed", 3, TIME, {"GripForce": 40.0}),
    "bare event": Event("homed", 1, TIME),
    "error": ErrorMessage("malformed", "not XML", "17"),
    "error without ref": ErrorMessage("unexpected", "a hello is not expected"),
    "bye": Bye("device stopping"),
    "bye without reason": Bye(),
}


@pytest.mark.parametrize("message", MESSAGES.values(), ids=MESSAGES.keys())
def test_encode_then_decode_gives_the_message_back(message: Message) -> None:
    assert decode(encode(message)) == message


@pytest.mark.parametrize("message", MESSAGES.values(), ids=MESSAGES.keys())
def test_every_encoded_message_is_valid_against_the_shipped_schema(message: Message) -> None:
    root = etree.fromstring(encode(message))
    assert schema().validate(root), schema().error_log.last_error


@pytest.mark.parametrize(
    "text",
    [
        "a & b < c > d",
        "quote \" and apostrophe '",
        "lines\nand\ttabs",
        "carriage\r\nreturn",
        "ünïcödé ✓",
        "  padded  ",
        "",
    ],
)
def test_text_survives_in_strings_attributes_and_failures(text: str) -> None:
    for message in (
        Request("1", "Say", {"Text": text}),
        Hello("d", "http://x/#C", label=text),
        Response("1", failure=Failure("failed", text)),
        Bye(text),
    ):
        assert decode(encode(message)) == message


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (1e-7, 1e-7),
        (1e16, 1e16),
        (-0.0, -0.0),
        (Decimal("1.50"), 1.5),
        (Decimal("1E+3"), 1000.0),
        (40, 40),
        (True, True),
        ([0, 0, 1, 0, 90, 0], Pose(0.0, 0.0, 1.0, 0.0, 90.0, 0.0)),
        ((1, 2, 3, 4, 5, 6.5), Pose(1.0, 2.0, 3.0, 4.0, 5.0, 6.5)),
    ],
)
def test_values_are_typed_on_the_wire(value: object, expected: object) -> None:
    decoded = decode(encode(Request("1", "Set", {"V": value})))  # type: ignore[dict-item]
    assert isinstance(decoded, Request)
    assert decoded.params["V"] == expected
    assert type(decoded.params["V"]) is type(expected)


def test_a_decimal_is_written_without_exponent() -> None:
    assert b">0.0000001<" in encode(Request("1", "Set", {"V": 1e-7}))
    assert b">10000000000000000<" in encode(Request("1", "Set", {"V": 1e16}))


@pytest.mark.parametrize(
    ("message", "complaint"),
    [
        (Request("1", "Set", {"V": float("nan")}), "not a finite number"),
        (Request("1", "Set", {"V": float("inf")}), "not a finite number"),
        (Request("1", "Set", {"V": [1, 2, 3, 4, 5]}), "a pose has six numbers"),  # type: ignore[dict-item]
        (Request("1", "Set", {"V": {"a": 1}}), "expected a decimal, integer"),  # type: ignore[dict-item]
        (Request("1", "Set", {"V": [1, 2, 3, 4, 5, "x"]}), "not a finite number"),  # type: ignore[dict-item]
        (Request("1", "Set", {"bad name": 1}), "parameter name 'bad name' is refused"),
        (Request("1", "9lives"), "name '9lives' is refused"),
        (Request("no spaces", "Open"), "id 'no spaces' is refused"),
        (Request("1", "Say", {"Text": "bell \x07"}), "U+0007"),
        (Hello("gripper", "http://x/#C", label="nul \x00"), "U+0000"),
        (Event("e", 1, datetime(2024, 1, 1)), "expected an aware (UTC) datetime"),
        (Event("e", 0, TIME), "sequence number 0"),
        (Response("1", {"R": 1}, failure=Failure("failed", "x")), "cannot carry results"),
        (Response("1", failure=Failure("Not OK", "x")), "failure code 'Not OK'"),
        (ErrorMessage("malformed", "x", "bad ref!"), "ref 'bad ref!'"),
    ],
)
def test_a_message_that_cannot_be_sent_is_refused_before_sending(message: Message, complaint: str) -> None:
    with pytest.raises(MessageError) as caught:
        encode(message)
    assert caught.value.code == "invalid-value"
    assert complaint in str(caught.value)


def test_a_time_in_another_zone_keeps_its_instant() -> None:
    there = TIME.astimezone(timezone(timedelta(hours=2)))
    decoded = decode(encode(Event("e", 1, there)))
    assert isinstance(decoded, Event)
    assert decoded.time == TIME


def test_a_time_without_zone_is_taken_as_utc() -> None:
    decoded = decode(f'<event {NS} name="e" seq="1" time="2024-05-17T09:30:12"/>'.encode())
    assert isinstance(decoded, Event)
    assert decoded.time == datetime(2024, 5, 17, 9, 30, 12, tzinfo=UTC)


def test_comments_and_cdata_inside_a_value_do_not_cut_it() -> None:
    data = f'<request {NS} id="1" name="Say"><string name="T">ab<!-- c -->cd<![CDATA[<e>]]></string></request>'
    assert decode(data.encode()) == Request("1", "Say", {"T": "abcd<e>"})


def test_a_response_without_results_is_an_ok() -> None:
    assert Response("1").ok
    assert not Response("1", failure=Failure("failed", "x")).ok


MALFORMED: dict[str, bytes] = {
    "empty": b"",
    "not XML": b"hello there",
    "not well-formed": f'<request {NS} id="1" name="Open">'.encode(),
    "DOCTYPE": f'<!DOCTYPE request [<!ENTITY x "y">]><request {NS} id="1" name="&x;"/>'.encode(),
    "no namespace": b'<request id="1" name="Open"/>',
    "other namespace": b'<request xmlns="urn:other" id="1" name="Open"/>',
    "unknown message": f"<reboot {NS}/>".encode(),
    "missing id": f'<request {NS} name="Open"/>'.encode(),
    "bad id": f'<request {NS} id="a b" name="Open"/>'.encode(),
    "bad name": f'<request {NS} id="1" name="1st"/>'.encode(),
    "unknown attribute": f'<request {NS} id="1" name="Open" force="yes"/>'.encode(),
    "unknown element": f'<request {NS} id="1" name="Open"><float name="F">1</float></request>'.encode(),
    "text in a request": f'<request {NS} id="1" name="Open">now</request>'.encode(),
    "duplicate parameter": f'<request {NS} id="1" name="S"><decimal name="V">1</decimal><integer name="V">2</integer>'
    f"</request>".encode(),
    "decimal with exponent": f'<request {NS} id="1" name="S"><decimal name="V">1e5</decimal></request>'.encode(),
    "decimal nan": f'<request {NS} id="1" name="S"><decimal name="V">NaN</decimal></request>'.encode(),
    "integer with fraction": f'<request {NS} id="1" name="S"><integer name="V">1.5</integer></request>'.encode(),
    "boolean yes": f'<request {NS} id="1" name="S"><boolean name="V">yes</boolean></request>'.encode(),
    "pose of five": f'<request {NS} id="1" name="S"><pose name="P">1 2 3 4 5</pose></request>'.encode(),
    "pose of seven": f'<request {NS} id="1" name="S"><pose name="P">1 2 3 4 5 6 7</pose></request>'.encode(),
    "value without name": f'<request {NS} id="1" name="S"><decimal>1</decimal></request>'.encode(),
    "failure with results": f'<response {NS} id="1"><failure code="failed">x</failure><string name="R">r</string>'
    f"</response>".encode(),
    "two failures": f'<response {NS} id="1"><failure code="a">x</failure><failure code="b">y</failure></response>'.encode(),
    "failure code in capitals": f'<response {NS} id="1"><failure code="FAILED">x</failure></response>'.encode(),
    "event without time": f'<event {NS} name="e" seq="1"/>'.encode(),
    "event seq zero": f'<event {NS} name="e" seq="0" time="2024-01-01T00:00:00Z"/>'.encode(),
    "hello version zero": f'<hello {NS} version="0" device="d" class="http://x/#C"/>'.encode(),
    "latin-1 declared": f'<?xml version="1.0" encoding="ISO-8859-1"?><bye {NS}/>'.encode(),
    "nested too deep": (f"<bye {NS}>" + "<a>" * 70 + "</a>" * 70 + "</bye>").encode(),
}


@pytest.mark.parametrize("data", MALFORMED.values(), ids=MALFORMED.keys())
def test_malformed_messages_are_refused_with_a_reason(data: bytes) -> None:
    with pytest.raises(MessageError) as caught:
        decode(data, "message from 127.0.0.1:5000")
    assert caught.value.code == "malformed"
    assert str(caught.value).startswith("message from 127.0.0.1:5000")


NOT_XML = ("empty", "not XML", "not well-formed")
HARDENING = {"DOCTYPE": "DOCTYPE/ENTITY declarations are refused", "latin-1 declared": "expected UTF-8",
             "nested too deep": "nested 65 levels deep"}
"""Refused by the hardened reading before any schema: the reason names the rule."""
SCHEMA_INVALID = {name: data for name, data in MALFORMED.items() if name not in NOT_XML and name not in HARDENING}
_PARSER = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)


@pytest.mark.parametrize("data", SCHEMA_INVALID.values(), ids=SCHEMA_INVALID.keys())
def test_what_decode_refuses_the_schema_refuses_too(data: bytes) -> None:
    """The schema is the rule: decode's checks are no stricter, and no laxer, than xirp.xsd."""
    assert not schema().validate(etree.fromstring(data, parser=_PARSER))


@pytest.mark.parametrize("name", NOT_XML)
def test_what_is_not_xml_is_refused_by_the_xml_parser(name: str) -> None:
    with pytest.raises(etree.XMLSyntaxError):
        etree.fromstring(MALFORMED[name], parser=_PARSER)
    with pytest.raises(MessageError, match="malformed XML"):
        decode(MALFORMED[name], "x")


@pytest.mark.parametrize(("name", "rule"), HARDENING.items())
def test_hardening_refuses_before_the_schema_and_names_its_rule(name: str, rule: str) -> None:
    etree.fromstring(MALFORMED[name], parser=_PARSER)  # well-formed XML: refused for safety, not for syntax
    with pytest.raises(MessageError, match=re.escape(rule)):
        decode(MALFORMED[name], "x")


def test_a_refused_request_names_its_id_when_it_can() -> None:
    with pytest.raises(MessageError) as schema_invalid:
        decode(MALFORMED["unknown element"])
    assert schema_invalid.value.ref == "1"
    with pytest.raises(MessageError) as not_xml:
        decode(f'<request {NS} id="42" name="Open"'.encode())
    assert not_xml.value.ref == "42"


BARE: dict[str, bytes] = {
    "response": f'<response {NS} id="17"/>'.encode(),
    "request": f'<request {NS} id="17" name="Open"/>'.encode(),
    "response, spaced": f'<response {NS} id="17" />'.encode(),
    "response, single quotes": f"<response xmlns='{NAMESPACE}' id='17'/>".encode(),
    "response, prefixed": f'<x:response xmlns:x="{NAMESPACE}" id="17"/>'.encode(),
    "response, declaration": f'<?xml version="1.0"?><response {NS} id="17"/>'.encode(),
    "response, bad id": f'<response {NS} id="1 7"/>'.encode(),
    "request, attributes swapped": f'<request {NS} name="Open" id="17"/>'.encode(),
    "request, bad name": f'<request {NS} id="17" name="9"/>'.encode(),
    "request, other namespace": b'<request xmlns="urn:plugnproduce-org:xirp:2" id="17" name="Open"/>',
}
_POSE = '<pose name="Target">0.4 0.1 0.2 0.0 180.0 -90.5</pose>'
TYPED: dict[str, bytes] = {
    "request": f'<request {NS} id="17" name="MoveTo">{_POSE}<decimal name="Speed">0.25</decimal>'
               '<integer name="Repeat">-3</integer><boolean name="Careful">true</boolean></request>'.encode(),
    "response": f'<response {NS} id="7"><decimal name="Force">39.5</decimal><boolean name="Ok">false</boolean>'
                '</response>'.encode(),
    "request, leading zeros and -0": f'<request {NS} id="1" name="A"><decimal name="x">-007.50</decimal>'
                                     '<integer name="n">-0</integer></request>'.encode(),
    "request, a name twice": f'<request {NS} id="1" name="A"><decimal name="x">1</decimal>'
                             '<decimal name="x">2</decimal></request>'.encode(),
    "response, a name twice": f'<response {NS} id="1"><boolean name="x">true</boolean>'
                              '<integer name="x">2</integer></response>'.encode(),
    "request, exponent": f'<request {NS} id="1" name="A"><decimal name="x">1e5</decimal></request>'.encode(),
    "request, boolean 1": f'<request {NS} id="1" name="A"><boolean name="x">1</boolean></request>'.encode(),
    "request, pose of five": f'<request {NS} id="1" name="A"><pose name="p">1 2 3 4 5</pose></request>'.encode(),
    "request, pose of seven": f'<request {NS} id="1" name="A"><pose name="p">1 2 3 4 5 6 7</pose></request>'.encode(),
    "request, integer as decimal": f'<request {NS} id="1" name="A"><integer name="n">1.5</integer></request>'.encode(),
    "request, huge integer": f'<request {NS} id="1" name="A"><integer name="n">{"9" * 30}</integer>'
                             '</request>'.encode(),
    "request, string": f'<request {NS} id="1" name="A"><string name="s">a &amp; b</string></request>'.encode(),
    "request, bad value name": f'<request {NS} id="1" name="A"><decimal name="9x">1</decimal></request>'.encode(),
    "request, unknown element": f'<request {NS} id="1" name="A"><float name="x">1</float></request>'.encode(),
    "request, spaced": f'<request {NS} id="1" name="A"><decimal name="x"> 1</decimal></request>'.encode(),
    "request, comment": f'<request {NS} id="1" name="A"><decimal name="x">1<!-- c --></decimal></request>'.encode(),
    "response, failure": f'<response {NS} id="1"><failure code="busy">no</failure></response>'.encode(),
}


@pytest.mark.parametrize("data", [*BARE.values(), *TYPED.values()], ids=[*BARE, *(f"typed {k}" for k in TYPED)])
def test_the_fast_path_for_bare_messages_agrees_with_the_full_path(data: bytes) -> None:
    try:
        full: Message | MessageError = _decode_document(data, "x")
    except MessageError as exc:
        full = exc
    try:
        fast: Message | MessageError = decode(data, "x")
    except MessageError as exc:
        fast = exc
    if isinstance(full, MessageError):
        assert isinstance(fast, MessageError)
        assert fast.code == full.code
    else:
        assert fast == full


def test_requests_and_responses_with_numbers_are_read_without_the_full_path(monkeypatch: pytest.MonkeyPatch) -> None:
    def full_path(data: bytes, source: str) -> Message:
        raise AssertionError("took the full path")

    monkeypatch.setattr("plugnproduce.protocols.xirp.decoding._decode_document", full_path)
    assert decode(TYPED["request"]) == Request("17", "MoveTo", {"Target": POSE, "Speed": 0.25, "Repeat": -3,
                                                                "Careful": True})
    assert decode(encode(Response("7", {"Force": 39.5, "Done": True}))) == Response("7", {"Force": 39.5, "Done": True})
    with pytest.raises(AssertionError, match="full path"):
        decode(TYPED["request, a name twice"])


def test_the_canonical_bare_messages_are_what_encode_writes() -> None:
    assert encode(Response("17")) == BARE["response"]
    assert encode(Request("17", "Open")) == BARE["request"]


def test_a_frame_is_a_big_endian_length_and_the_document() -> None:
    data = encode_frame(Bye())
    assert data[:4] == len(data[4:]).to_bytes(4, "big")
    assert frame_length(data[:4]) == len(data) - 4
    assert frame(b"abc") == b"\x00\x00\x00\x03abc"
    assert MAX_FRAME == 65536


def test_device_files_come_back_from_the_documents_of_a_describe_response() -> None:
    files = DeviceFiles("gripper.ttl", "@prefix pnp: <x#> .\n", "gripper.scxml", "<scxml/>")
    assert files_from_documents(documents_of(files), "describe") == files
    with pytest.raises(MessageError, match="expected a application/scxml"):
        files_from_documents(documents_of(files)[:1], "describe of gripper")
    with pytest.raises(DescriptionError, match="plain file name"):
        DeviceFiles("../etc/passwd", "", "g.scxml", "")
    bad = (Document("../x.ttl", TURTLE, ""), Document("g.scxml", SCXML, ""))
    with pytest.raises(MessageError, match="describe of gripper: .*plain file name"):
        files_from_documents(bad, "describe of gripper")


def test_one_device_files_class_serves_both_protocols() -> None:
    assert xirp.DeviceFiles is upnp.DeviceFiles


@pytest.mark.parametrize(
    ("endpoint", "expected"),
    [
        ("xirp://127.0.0.1:4840", ("127.0.0.1", 4840)),
        ("xirp://gripper.local:1/", ("gripper.local", 1)),
        ("xirp://[::1]:9", ("::1", 9)),
    ],
)
def test_endpoints_are_read_and_written(endpoint: str, expected: tuple[str, int]) -> None:
    assert parse_endpoint(endpoint) == expected
    assert parse_endpoint(format_endpoint(*expected)) == expected


@pytest.mark.parametrize(
    "endpoint", ["http://127.0.0.1:80", "xirp://127.0.0.1", "xirp://127.0.0.1:70000", "xirp://a b:1"]
)
def test_a_bad_endpoint_is_refused(endpoint: str) -> None:
    with pytest.raises(ProtocolError, match="expected xirp://HOST:PORT"):
        parse_endpoint(endpoint)
