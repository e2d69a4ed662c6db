"""The hardened reading every description goes through: the DOCTYPE rule in every encoding."""

from __future__ import annotations

import pytest

from plugnproduce.errors import HostileInputError
from plugnproduce.safeio import parse_xml_bytes

SCXML = '<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="a"><state id="a"/></scxml>'
DOCTYPE = '<!DOCTYPE scxml [<!ENTITY a "aaaa">]>\n'


@pytest.mark.parametrize("codec", ["utf-16", "utf-16-le", "utf-16-be", "utf-32", "utf-32-le", "utf-32-be"])
def test_a_doctype_is_refused_in_a_wide_encoding(codec: str) -> None:
    data = (f'<?xml version="1.0" encoding="{codec.upper()}"?>\n' + DOCTYPE + SCXML).encode(codec)
    with pytest.raises(HostileInputError, match="DOCTYPE/ENTITY declarations are refused") as caught:
        parse_xml_bytes(data, "chart.scxml")
    assert caught.value.location_message().startswith("chart.scxml:")


def test_a_doctype_is_refused_at_its_line() -> None:
    with pytest.raises(HostileInputError) as caught:
        parse_xml_bytes(('<?xml version="1.0"?>\n<!-- a\n comment -->\n' + DOCTYPE + SCXML).encode(), "c.scxml")
    assert caught.value.line == 4


def test_the_word_doctype_inside_a_comment_is_only_a_comment() -> None:
    data = ("<!-- an example: <!DOCTYPE x> and <!ENTITY y 'z'> are refused -->\n" + SCXML).encode()
    assert parse_xml_bytes(data, "chart.scxml").getroot().get("initial") == "a"
