"""The hardened reading every description goes through: the DOCTYPE rule in every encoding, YAML values."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from plugnproduce.errors import DescriptionError, HostileInputError
from plugnproduce.safeio import parse_xml_bytes, parse_yaml_node, read_bytes

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


TASK = "task: t\nsteps:\n  - command: pick\n    params:\n      grip_force: {value}\n"


@pytest.mark.parametrize(("value", "needle"), [
    (".nan", ".nan is not a number a device can be given"),
    ("-.inf", "-.inf is not a number a device can be given"),
    (".Inf", ".Inf is not a number a device can be given"),
    ("9" * 5000, "an integer of 5000 digits"),
    ("!!timestamp 2020-13-45", "YAML type !!timestamp is not accepted"),
    ("2020-01-01", "YAML type !!timestamp is not accepted"),
    ("!!omap [a: 1]", "YAML type !!omap is not accepted"),
    ("!!binary aGVsbG8=", "YAML type !!binary is not accepted"),
    ("!!python/object:os.system x", "YAML type !!python/object:os.system is not accepted"),
], ids=["nan", "-inf", "Inf", "5000 digits", "bad timestamp", "date", "omap", "binary", "python object"])
def test_a_value_no_description_needs_is_refused_at_its_line(tmp_path: Path, value: str, needle: str) -> None:
    f = tmp_path / "task.yaml"
    f.write_text(TASK.format(value=value))
    with pytest.raises(DescriptionError) as caught:
        parse_yaml_node(f)
    assert caught.value.line == 5 and needle in caught.value.message


@pytest.mark.parametrize("text", ["[" * 100_000, "a:\n" + "".join("  " * n + f"k{n}:\n" for n in range(1, 200))],
                         ids=["flow", "block"])
def test_deeply_nested_yaml_is_refused(tmp_path: Path, text: str) -> None:
    f = tmp_path / "deep.yaml"
    f.write_text(text)
    with pytest.raises(HostileInputError, match="nested"):
        parse_yaml_node(f)


def test_plain_values_pass(tmp_path: Path) -> None:
    f = tmp_path / "task.yaml"
    f.write_text(TASK.format(value="[0.6, -0.2, 1e-3, 12, true, null, 'text', \"2020-01-01\"]"))
    params = parse_yaml_node(f).value[1][1].value[0].value[1][1]
    assert [n.value for n in params.value[0][1].value] == ["0.6", "-0.2", "1e-3", "12", "true", "null", "text",
                                                           "2020-01-01"]


def test_a_pipe_named_as_a_description_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "chart.scxml"
    os.mkfifo(fifo)
    with pytest.raises(DescriptionError, match="not a regular file"):
        read_bytes(fifo)


def test_a_folder_named_as_a_description_is_refused(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match="not a regular file"):
        read_bytes(tmp_path)
