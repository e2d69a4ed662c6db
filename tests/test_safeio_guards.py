"""Safe parsing at its limits: what is accepted just below each bound and refused just above,
each refusal naming the file and line; YAML read with the nodes the pure-Python loader makes."""

from __future__ import annotations

import codecs
import tracemalloc
from pathlib import Path

import pytest
import rdflib
import yaml
from lxml import etree

from plugnproduce.errors import HostileInputError, UnreadableError
from plugnproduce.safeio import (
    MAX_BYTES,
    MAX_DIGITS,
    MAX_TRIPLES,
    MAX_XML_ATTRIBUTES,
    MAX_XML_DEPTH,
    MAX_XML_ELEMENTS,
    MAX_YAML_DEPTH,
    PlainDumper,
    parse_turtle,
    parse_turtle_bytes,
    parse_xml,
    parse_xml_bytes,
    parse_yaml_bytes,
    parse_yaml_node,
    read_bytes,
    shown,
)
from tests.test_safeio_yaml import _signature


def nested_sequences(levels: int) -> str:
    """A value inside ``levels`` nested lists, counted with the value: ``[[1]]`` is 3 levels."""
    return "[" * (levels - 1) + "1" + "]" * (levels - 1)


def nested_mappings(levels: int) -> str:
    """A value inside ``levels - 1`` nested mappings (block style, the way descriptions are written)."""
    lines = [" " * i + "a:" for i in range(levels - 1)]
    return "\n".join(lines) + " 1\n"


@pytest.mark.parametrize("nested", [nested_sequences, nested_mappings])
def test_a_value_as_deep_as_the_limit_is_read_and_one_level_more_is_refused(nested) -> None:  # type: ignore[no-untyped-def]
    parse_yaml_bytes(nested(MAX_YAML_DEPTH).encode(), "deep.yaml")
    with pytest.raises(HostileInputError, match="nested") as caught:
        parse_yaml_bytes(nested(MAX_YAML_DEPTH + 1).encode(), "deep.yaml")
    assert caught.value.file == "deep.yaml"


@pytest.mark.parametrize("number", ["9" * MAX_DIGITS, "-" + "9" * MAX_DIGITS, "1_" + "0" * (MAX_DIGITS - 1)])
def test_an_integer_of_the_longest_length_is_read(number: str) -> None:
    node = parse_yaml_bytes(f"speed: {number}\n".encode(), "task.yaml")
    assert isinstance(node, yaml.MappingNode) and node.value[0][1].value == number


@pytest.mark.parametrize(("text", "line", "needle"), [
    (f"a: 1\nspeed: {'9' * (MAX_DIGITS + 1)}\n", 2, f"an integer of {MAX_DIGITS + 1} digits"),
    ("a: 1\nb: 2\nforce: .NaN\n", 3, ".NaN is not a number"),
    ("force: -.inf\n", 1, "-.inf is not a number"),
])
def test_a_number_no_device_can_be_given_is_refused_at_its_file_and_line(text: str, line: int, needle: str) -> None:
    with pytest.raises(UnreadableError, match=needle) as caught:
        parse_yaml_bytes(text.encode(), "task.yaml")
    assert (caught.value.file, caught.value.line) == ("task.yaml", line)


def test_quoted_plain_block_and_untagged_scalars_are_read_as_the_pure_python_loader_reads_them() -> None:
    text = "a: 'x'\nb: \"y\"\nc: z\nd: |\n  block\ne: >\n  folded\nf: ! 12\ng: !!str 13\nh: ! [1]\ni: ! {j: 2}\n"
    assert _signature(parse_yaml_bytes(text.encode(), "t.yaml")) == \
        _signature(yaml.compose(text, Loader=yaml.SafeLoader))


@pytest.mark.parametrize("text", ["", "# only a comment\n"])
def test_an_empty_yaml_document_is_refused_at_line_1(text: str) -> None:
    with pytest.raises(UnreadableError, match="empty YAML document") as caught:
        parse_yaml_bytes(text.encode(), "empty.yaml")
    assert caught.value.line == 1


def test_a_value_shared_by_two_places_is_written_out_at_each_and_reads_back() -> None:
    pose = [0.1, 0.2, 0.3]
    text = yaml.dump({"first": pose, "second": pose}, Dumper=PlainDumper)
    assert "&" not in text and "*" not in text
    parse_yaml_bytes(text.encode(), "task.yaml")  # anchors and aliases would be refused here


def test_an_xml_file_is_read_with_the_hardened_parser_naming_the_file(tmp_path: Path) -> None:
    good, deep = tmp_path / "chart.scxml", tmp_path / "deep.scxml"
    good.write_text("<scxml><state id='a'/></scxml>", encoding="utf-8")
    assert parse_xml(good).getroot()[0].get("id") == "a"
    deep.write_text("<a>" * (MAX_XML_DEPTH + 1) + "</a>" * (MAX_XML_DEPTH + 1), encoding="utf-8")
    with pytest.raises(HostileInputError, match="nested") as caught:
        parse_xml(deep)
    assert caught.value.file == str(deep)


@pytest.mark.parametrize(("text", "line"), [("a: \x07\nb: 1\nc: 2\n", 1), ("\n\nc: \x07\n", 3), ("\x07", 1),
                                            ("a: 1\nb: \x01\nc: \x01\n", 2)])
def test_a_character_yaml_does_not_allow_is_refused_at_its_line(text: str, line: int) -> None:
    with pytest.raises(UnreadableError, match="expected printable text") as caught:
        parse_yaml_bytes(text.encode(), "task.yaml")
    assert (caught.value.file, caught.value.line) == ("task.yaml", line)


def test_yaml_of_the_largest_size_is_read_and_one_byte_more_is_refused() -> None:
    text = b"a: 1\n#" + b"x" * (MAX_BYTES - 7) + b"\n"
    assert len(text) == MAX_BYTES
    parse_yaml_bytes(text, "big.yaml")
    with pytest.raises(HostileInputError, match=f"at most {MAX_BYTES}"):
        parse_yaml_bytes(text + b"\n", "big.yaml")


def test_yaml_nested_deeper_than_the_reader_goes_is_refused_naming_the_file(tmp_path: Path) -> None:
    deep = tmp_path / "deep.yaml"
    deep.write_text("[" * (MAX_YAML_DEPTH + 1), encoding="utf-8")
    with pytest.raises(HostileInputError, match="nested more than") as caught:
        parse_yaml_node(deep)
    assert (caught.value.file, caught.value.line) == (str(deep), 1)


def test_xml_at_each_bound_is_read_and_one_more_is_refused() -> None:
    parse_xml_bytes(("<a>" * MAX_XML_DEPTH + "</a>" * MAX_XML_DEPTH).encode(), "deep.xml")
    attributes = " ".join(f'a{i}="1"' for i in range(MAX_XML_ATTRIBUTES))
    parse_xml_bytes(f"<a {attributes}/>".encode(), "wide.xml")
    with pytest.raises(HostileInputError, match=f"an element with {MAX_XML_ATTRIBUTES + 1} attributes"):
        parse_xml_bytes(f'<a {attributes} z="1"/>'.encode(), "wide.xml")
    many = "<a>" + "<b/>" * (MAX_XML_ELEMENTS - 1) + "</a>"
    parse_xml_bytes(many.encode(), "many.xml")
    with pytest.raises(HostileInputError, match=f"more than {MAX_XML_ELEMENTS} XML elements") as caught:
        parse_xml_bytes(many.replace("</a>", "<b/></a>").encode(), "many.xml")
    assert caught.value.file == "many.xml"


def test_malformed_xml_is_one_line_at_its_line_naming_the_file() -> None:
    with pytest.raises(UnreadableError, match="^chart.scxml:3: malformed XML: ") as caught:
        parse_xml_bytes(b"<a>\n<b>\n</a>", "chart.scxml")
    assert "line 3" not in str(caught.value) and "\n" not in str(caught.value)


def test_a_file_of_the_largest_size_is_read_and_one_byte_more_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "d.ttl"
    path.write_bytes(b"#" * 100)
    assert read_bytes(path, limit=100) == b"#" * 100
    path.write_bytes(b"#" * 101)
    with pytest.raises(HostileInputError, match="101 bytes; at most 100") as caught:
        read_bytes(path, limit=100)
    assert caught.value.file == str(path)


def test_a_path_from_the_input_is_shown_whole_up_to_200_characters_and_by_its_ends_beyond() -> None:
    assert shown("d/" + "x" * 198) == "d/" + "x" * 198
    long = "d/" + "x" * 199
    assert shown(long) != long and len(shown(long)) < 130 and shown(long).startswith("d/x")
    name = "robot_cell_gripper_description_v2.ttl"  # the end of a long path, its file name, is shown whole
    assert shown("/" + "d" * 300 + "/" + name).endswith("d/" + name)


@pytest.mark.parametrize("text", [f"serial: '{'9' * (MAX_DIGITS + 1)}'\n", "mode: '.nan'\n", "mode: \".inf\"\n"])
def test_quoted_text_that_looks_like_a_refused_number_is_read_as_text(text: str) -> None:
    node = parse_yaml_bytes(text.encode(), "task.yaml")
    assert isinstance(node, yaml.MappingNode) and node.value[0][1].tag == "tag:yaml.org,2002:str"


def test_a_character_yaml_does_not_allow_after_non_ascii_text_is_refused_at_its_own_line() -> None:
    # libyaml counts the position of the character in bytes: two two-byte letters before it shift it by two
    with pytest.raises(UnreadableError, match="expected printable text") as caught:
        parse_yaml_bytes("greeting: Grüße\x07\nnext: 1\nlast: 2\n".encode(), "task.yaml")
    assert caught.value.line == 1


def test_malformed_xml_names_what_is_wrong() -> None:
    with pytest.raises(UnreadableError, match="malformed XML: Opening and ending tag mismatch: b") as caught:
        parse_xml_bytes(b"<a>\n<b>\n</a>", "chart.scxml")
    assert caught.value.line == 3


def test_a_parser_failure_without_a_message_or_line_is_still_malformed_xml_naming_the_file(
        monkeypatch: pytest.MonkeyPatch) -> None:
    def failing(*args: object, **kwargs: object) -> None:  # lxml's failure when libxml2 gives no reason
        raise etree.XMLSyntaxError(None, 1, 0, 0)

    monkeypatch.setattr(etree, "fromstring", failing)
    with pytest.raises(UnreadableError) as caught:
        parse_xml_bytes(b"<a/>", "chart.scxml")
    assert caught.value.location_message() == "chart.scxml: malformed XML: the parser gave no reason"


@pytest.mark.parametrize("codec", ["utf-16", "utf-16-le", "utf-32-be"])
def test_a_doctype_in_a_wide_encoding_is_refused_at_its_line(codec: str) -> None:
    data = '<?xml version="1.0"?>\n<!-- a\ncomment -->\n<!DOCTYPE a [<!ENTITY e "x">]>\n<a>&e;</a>'.encode(codec)
    with pytest.raises(HostileInputError, match="DOCTYPE/ENTITY declarations are refused") as caught:
        parse_xml_bytes(data, "chart.scxml")
    assert caught.value.line == 4


@pytest.mark.parametrize("data", [codecs.BOM_UTF16_LE + "<a>\n<b/>".encode("utf-16-le") + b"\x00\xd8",
                                  codecs.BOM_UTF32_BE + "<a/>".encode("utf-32-be") + b"\xff\xff\xff\xff"],
                         ids=["utf-16 lone surrogate", "utf-32 beyond unicode"])
def test_wide_xml_with_bytes_no_character_has_is_refused_as_malformed(data: bytes) -> None:
    with pytest.raises(UnreadableError, match="malformed XML") as caught:
        parse_xml_bytes(data, "chart.scxml")
    assert caught.value.file == "chart.scxml"


def test_a_doctype_in_an_encoding_the_search_does_not_know_is_refused_unexpanded() -> None:
    # in UTF-7 '<' may be written '+ADw-': the byte-wise search sees no '<!DOCTYPE', the parser does
    data = (b'<?xml version="1.0" encoding="UTF-7"?>\n+ADw-!DOCTYPE a [+ADw-!ENTITY e SYSTEM "/etc/hostname">]>\n'
            b"<a>&e;</a>")
    with pytest.raises(HostileInputError, match="DOCTYPE/ENTITY declarations are refused") as caught:
        parse_xml_bytes(data, "chart.scxml")
    assert (caught.value.file, caught.value.line) == ("chart.scxml", 1)


@pytest.mark.skipif(not Path("/proc/self/smaps").is_file(), reason="needs Linux's /proc")
def test_a_file_that_reports_no_size_is_read_no_further_than_the_limit() -> None:
    smaps = Path("/proc/self/smaps")  # the kernel's files say they are empty; this one is tens of kB at least
    assert smaps.stat().st_size == 0 and len(smaps.read_bytes()) > 20_000
    tracemalloc.start()
    try:
        with pytest.raises(HostileInputError, match="larger than the 100 bytes accepted") as caught:
            read_bytes(smaps, limit=100)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert caught.value.file == str(smaps) and peak < 10_000


def test_turtle_of_the_largest_size_is_read_and_one_byte_more_is_refused_naming_the_file() -> None:
    head = b"@prefix p: <http://example.org/> .\np:a p:b p:c .\n#"
    data = head + b"x" * (MAX_BYTES - len(head) - 1) + b"\n"
    assert len(parse_turtle_bytes(data, "big.ttl")[0]) == 1
    with pytest.raises(HostileInputError, match=f"at most {MAX_BYTES}") as caught:
        parse_turtle_bytes(data + b"\n", "big.ttl")
    assert caught.value.file == "big.ttl"


def test_turtle_of_the_most_triples_is_read_and_one_more_is_refused() -> None:
    def objects(count: int) -> bytes:
        return f"@prefix p: <http://example.org/> .\np:s p:p {', '.join(map(str, range(count)))} .\n".encode()

    assert len(parse_turtle_bytes(objects(MAX_TRIPLES), "d.ttl")[0]) == MAX_TRIPLES
    with pytest.raises(HostileInputError, match=f"{MAX_TRIPLES + 1} triples; at most {MAX_TRIPLES}"):
        parse_turtle_bytes(objects(MAX_TRIPLES + 1), "d.ttl")


def test_malformed_turtle_is_refused_at_its_file_and_line(tmp_path: Path) -> None:
    f = tmp_path / "d.ttl"
    f.write_text("@prefix p: <http://example.org/> .\np:a p:b\n  p:c p:d .\n", encoding="utf-8")
    with pytest.raises(UnreadableError, match="malformed Turtle: expected '.'") as caught:
        parse_turtle(f)
    assert (caught.value.file, caught.value.line) == (str(f), 3)


def test_turtle_that_is_not_utf8_is_refused_naming_the_file() -> None:
    with pytest.raises(UnreadableError, match="not UTF-8 text") as caught:
        parse_turtle_bytes(b"# caf\xe9\n", "d.ttl")
    assert caught.value.file == "d.ttl"


def test_relative_iris_of_turtle_resolve_against_its_path_which_is_not_read(tmp_path: Path) -> None:
    path = tmp_path / "cell" / "arm.ttl"  # no such file
    graph, _ = parse_turtle_bytes(b"<#arm> a <#Robot> .\n", path)
    arm = rdflib.URIRef(path.as_uri() + "#arm")
    assert set(graph) == {(arm, rdflib.RDF.type, rdflib.URIRef(path.as_uri() + "#Robot"))}
