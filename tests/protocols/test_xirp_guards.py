"""The XIRP codec's guards: what it refuses to write or read, and what it must still carry.

A peer that sends a pose with a 5,000-digit number, an event numbered beyond any counter,
or a value the schema cannot hold is refused with ``malformed``; the controller never sends
what the peer could not read (an exponent, ``inf``, a string or a boolean where a number
belongs). Values of subclasses of the plain types (a float that carries a unit, a string
enum) travel as their plain values.
"""

from __future__ import annotations

import math
import re
from datetime import UTC, datetime
from decimal import Decimal

import pytest

from plugnproduce.protocols.xirp import NAMESPACE, Event, Hello, MessageError, Pose, Request, decode, encode
from plugnproduce.protocols.xirp.decoding import MAX_SEQ

TIME = datetime(2026, 1, 2, 3, 4, 5, tzinfo=UTC)


class Metres(float):
    """A float that carries its unit, as a units library hands it over."""


class Word(str):
    """A string subclass (a ``StrEnum`` member, a string with provenance)."""


def request(xml_values: str) -> bytes:
    return f'<request xmlns="{NAMESPACE}" id="7" name="Go">{xml_values}</request>'.encode()


# --- reading what a peer sends ------------------------------------------------------------


@pytest.mark.parametrize("text", [
    "9" * 5000 + " 0 0 0 0 0",
    "0 0 0 0 0 -" + "9" * 400,
])
def test_a_pose_with_a_number_too_large_for_a_float_is_refused(text: str) -> None:
    with pytest.raises(MessageError, match="holds a number too large") as caught:
        decode(request(f'<pose name="p">{text}</pose>'))
    assert caught.value.code == "malformed"


def test_a_decimal_too_large_for_a_float_is_refused() -> None:
    with pytest.raises(MessageError, match="too large for a number") as caught:
        decode(request(f'<decimal name="d">{"9" * 5000}</decimal>'))
    assert caught.value.code == "malformed"


def test_an_integer_of_5000_digits_is_refused_as_malformed() -> None:
    with pytest.raises(MessageError, match="5000 digits is too long") as caught:
        decode(request(f'<integer name="i">{"9" * 5000}</integer>'))
    assert caught.value.code == "malformed"


def test_large_but_finite_numbers_are_read() -> None:
    message = decode(request(f'<pose name="p">{"9" * 300} 0 0 0 0 -1.5</pose><decimal name="d">{"9" * 300}</decimal>'
                             f'<integer name="i">{"9" * 300}</integer>'))
    assert isinstance(message, Request)
    assert message.params["p"] == Pose(float("9" * 300), 0.0, 0.0, 0.0, 0.0, -1.5)
    assert message.params["d"] == float("9" * 300) and message.params["i"] == int("9" * 300)


def event(seq: str) -> bytes:
    return f'<event xmlns="{NAMESPACE}" name="moved" seq="{seq}" time="2026-01-01T00:00:00Z"/>'.encode()


def test_the_largest_event_number_is_read_and_one_more_is_refused() -> None:
    read = decode(event(str(MAX_SEQ)))
    assert isinstance(read, Event) and read.seq == MAX_SEQ and read.params == {}
    with pytest.raises(MessageError, match="larger than") as caught:
        decode(event(str(MAX_SEQ + 1)))
    assert caught.value.code == "malformed"


def test_an_event_time_without_zone_is_read_as_utc() -> None:
    data = f'<event xmlns="{NAMESPACE}" name="moved" seq="3" time="2026-01-01T00:00:00"/>'.encode()
    read = decode(data)
    assert isinstance(read, Event) and read.time == datetime(2026, 1, 1, tzinfo=UTC)


def test_an_event_time_python_cannot_read_is_refused_as_malformed() -> None:
    data = f'<event xmlns="{NAMESPACE}" name="moved" seq="3" time="2026-01-01T24:00:00Z"/>'.encode()
    with pytest.raises(MessageError, match="cannot be read") as caught:
        decode(data)
    assert caught.value.code == "malformed"


# --- writing what the controller sends ----------------------------------------------------


def sent(value: object) -> str:
    return encode(Request("7", "Go", {"v": value})).decode()  # type: ignore[dict-item]


@pytest.mark.parametrize("pose", [
    Pose(1e-20, 2.5e22, -3e-7, 0.0, 180.0, -90.5),
    (1e-20, 2.5e22, -3e-7, 0.0, 180.0, -90.5),
    [1e-20, 2.5e22, -3e-7, 0, Decimal("180"), -90.5],
], ids=["Pose", "tuple", "list"])
def test_a_pose_is_written_without_exponent_and_read_back_the_same(pose: object) -> None:
    text = sent(pose)
    written = re.search(r'<pose name="v">([^<]*)</pose>', text)
    assert written is not None and "e" not in written.group(1).lower()
    read = decode(text.encode())
    assert isinstance(read, Request)
    assert read.params["v"] == Pose(1e-20, 2.5e22, -3e-7, 0.0, 180.0, -90.5)


@pytest.mark.parametrize("pose", [
    Pose(math.inf, 0.0, 0.0, 0.0, 0.0, 0.0),
    Pose(0.0, 0.0, 0.0, 0.0, 0.0, math.nan),
    Pose(0.0, 0.0, 0.0, 0.0, 0.0, -math.inf),
    Pose("1", 0.0, 0.0, 0.0, 0.0, 0.0),  # type: ignore[arg-type]
    Pose("1", "2", "3", "4", "5", "6"),  # type: ignore[arg-type]
    (True, 0.0, 0.0, 0.0, 0.0, 0.0),
], ids=["inf", "nan", "-inf", "a string", "six strings", "a boolean"])
def test_a_pose_the_peer_could_not_read_is_not_sent(pose: object) -> None:
    with pytest.raises(MessageError, match="not a finite number") as caught:
        sent(pose)
    assert caught.value.code == "invalid-value"


def test_values_of_subclasses_travel_as_their_plain_values() -> None:
    read = decode(encode(Request("7", "Go", {"m": Metres(0.25), "w": Word("left"), "t": Metres(1e-9)})))
    assert isinstance(read, Request)
    assert read.params == {"m": 0.25, "w": "left", "t": 1e-9}


def test_a_value_of_no_xirp_type_is_refused_naming_the_types() -> None:
    with pytest.raises(MessageError, match="cannot be sent; expected a decimal, integer, boolean, string or pose"):
        sent({"a": 1})


@pytest.mark.parametrize("message", [
    Hello("gripper", "http://example.org/pnp#Gripper", version=True),
    Hello("gripper", "http://example.org/pnp#Gripper", version=0),
    Event("moved", True, TIME),
    Event("moved", 0, TIME),
], ids=["version True", "version 0", "seq True", "seq 0"])
def test_a_version_or_sequence_number_must_be_a_positive_integer(message: Hello | Event) -> None:
    with pytest.raises(MessageError, match="expected a positive integer"):
        encode(message)


@pytest.mark.parametrize("declared", ["utf-8", "UTF-8", "utf8", "UTF8"])
def test_a_message_declaring_utf8_in_any_spelling_is_read(declared: str) -> None:
    data = f'<?xml version="1.0" encoding="{declared}"?><request xmlns="{NAMESPACE}" id="7" name="Go"/>'.encode()
    assert decode(data) == Request("7", "Go", {})


def test_a_message_declaring_another_encoding_is_refused_naming_it() -> None:
    data = f'<?xml version="1.0" encoding="ISO-8859-1"?><request xmlns="{NAMESPACE}" id="7" name="Go"/>'.encode()
    with pytest.raises(MessageError, match="^peer: declared encoding ISO-8859-1; expected UTF-8$") as caught:
        decode(data)
    assert (caught.value.code, caught.value.ref) == ("malformed", "7")


def test_an_invalid_request_is_refused_in_one_line_naming_its_id_and_not_the_namespace() -> None:
    with pytest.raises(MessageError, match="^message from x: not a valid XIRP message: ") as caught:
        decode(request('<bogus name="p"/>'), "message from x")
    text = str(caught.value)
    assert (caught.value.code, caught.value.ref) == ("malformed", "7")
    assert NAMESPACE not in text and "{" not in text and "line" not in text and "\n" not in text
    assert text.endswith(": Element 'bogus': This element is not expected."
                         " Expected is one of ( decimal, integer, boolean, string, pose ).")


@pytest.mark.parametrize(("xml", "reason"), [
    (f'<x:decimal xmlns:x="{NAMESPACE}/ext" name="p">1</x:decimal>',
     "Element '{xirp/ext}decimal': This element is not expected."),
    ('<decimal xmlns="urn:example:units" name="p">1</decimal>',
     "Element '{urn:example:units}decimal': This element is not expected."),
], ids=["extending XIRP's", "another"])
def test_a_value_in_a_namespace_other_than_xirps_is_refused_naming_that_namespace(xml: str, reason: str) -> None:
    """XIRP's own namespace is written ``xirp`` (or left out), so a foreign one stands out against the expected names."""
    with pytest.raises(MessageError) as caught:
        decode(request(xml))
    expected = " Expected is one of ( decimal, integer, boolean, string, pose )."
    assert str(caught.value) == f"peer: not a valid XIRP message: {reason}{expected}"


def test_an_invalid_message_other_than_a_request_names_no_id() -> None:
    data = f'<response xmlns="{NAMESPACE}" id="7"><bogus/></response>'.encode()
    with pytest.raises(MessageError, match="not a valid XIRP message") as caught:
        decode(data)
    assert caught.value.ref is None


def test_an_invalid_request_with_an_id_no_reply_could_carry_names_no_id() -> None:
    data = f'<request xmlns="{NAMESPACE}" id="bad id" name="Go"/>'.encode()
    with pytest.raises(MessageError, match="not a valid XIRP message") as caught:
        decode(data)
    assert caught.value.ref is None


@pytest.mark.parametrize("name", ["has space", ["Go"], 7])
def test_a_request_name_that_is_not_a_name_is_refused_saying_what_a_name_is(name: object) -> None:
    with pytest.raises(MessageError, match=r"is refused; expected letters, digits, '_', '\.', '-'"):
        encode(Request("7", name, {}))  # type: ignore[arg-type]
