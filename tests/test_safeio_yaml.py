"""YAML is read through libyaml where present, with the pure-Python loader's nodes and error lines."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from plugnproduce import safeio
from plugnproduce.errors import HostileInputError, UnreadableError
from plugnproduce.safeio import MAX_YAML_DEPTH, _compose_yaml, parse_yaml_node

DESCRIPTIONS = Path(__file__).resolve().parents[1] / "descriptions"


def _signature(node: yaml.Node) -> tuple[object, ...]:
    """Everything the loader reads of a node: kind, tag, marks, style and children."""
    head = (type(node).__name__, node.tag, node.start_mark.line, node.start_mark.column, node.end_mark.line,
            node.end_mark.column, getattr(node, "style", None), getattr(node, "flow_style", None))
    if isinstance(node, yaml.ScalarNode):
        return (*head, node.value)
    if isinstance(node, yaml.SequenceNode):
        return (*head, *(_signature(c) for c in node.value))
    return (*head, *((_signature(k), _signature(v)) for k, v in node.value))


@pytest.mark.parametrize("path", sorted(DESCRIPTIONS.rglob("*.yaml")), ids=lambda p: p.name)
def test_nodes_are_those_of_the_pure_python_loader(path: Path) -> None:
    expected = yaml.compose(path.read_text(encoding="utf-8"), Loader=yaml.SafeLoader)
    assert _signature(parse_yaml_node(path)) == _signature(expected)


def test_tags_and_complex_keys_are_composed_alike(tmp_path: Path) -> None:
    text = "a: !!str 1\nb: x\n? [c]\n: {d: [1, 2.5, null, true]}\n"
    composed = _compose_yaml(text, "t.yaml")  # a complex key is refused after composing (see the fuzz regressions)
    assert composed is not None and _signature(composed) == _signature(yaml.compose(text, Loader=yaml.SafeLoader))


@pytest.mark.parametrize(
    "text",
    ["task: t\nsteps:\n  - command: [pick\n", "a: b: c\n", "a:\n  - x\n - y\n", "key: 'open\n", "- a\nb: c\n",
     "a: [1, 2\nb: 3\n", "\t- x\n", "a: 1\n---\nb: 2\n"],
)
def test_malformed_yaml_is_reported_at_the_pure_python_loaders_line(tmp_path: Path, text: str) -> None:
    f = tmp_path / "t.yaml"
    f.write_text(text)
    with pytest.raises(yaml.MarkedYAMLError) as expected:
        yaml.compose(text, Loader=yaml.SafeLoader)
    mark = expected.value.problem_mark or expected.value.context_mark
    assert mark is not None
    with pytest.raises(UnreadableError, match="malformed YAML") as found:
        parse_yaml_node(f)
    assert found.value.line == mark.line + 1


@pytest.mark.parametrize(("text", "what", "line"), [("a: &x 1\nb: *x\n", "anchors", 1),
                                                    ("a: [1]\nb: *x\n", "aliases", 2)])
def test_anchors_and_aliases_are_refused_with_their_line(tmp_path: Path, text: str, what: str, line: int) -> None:
    f = tmp_path / "t.yaml"
    f.write_text(text)
    with pytest.raises(UnreadableError, match=f"{what} are refused") as found:
        parse_yaml_node(f)
    assert found.value.line == line


@pytest.mark.parametrize("depth", [MAX_YAML_DEPTH + 1, 1_000_000])
def test_deep_nesting_is_refused_not_a_crash(tmp_path: Path, depth: int) -> None:
    # libyaml's own composer recurses in C: a million '[' would end the process.
    f = tmp_path / "deep.yaml"
    f.write_text("[" * depth)
    with pytest.raises(HostileInputError, match="nested more than") as found:
        parse_yaml_node(f)
    assert found.value.line == 1


LOADERS = [yaml.SafeLoader, *([yaml.CSafeLoader] if hasattr(yaml, "CSafeLoader") else [])]


@pytest.mark.parametrize("text", ["[" * 100, "[" * 5_000, "{a: " * 5_000, "".join("  " * n + f"k{n}:\n" for n in range(1_200))],
                         ids=["flow-100", "flow-5000", "mapping-5000", "block-1200"])
def test_deep_nesting_gets_one_refusal_whichever_layer_finds_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                text: str) -> None:
    # PyYAML 6.0.4's libyaml stops at about 1,000 levels itself, before our composer sees the events;
    # the pure-Python parser leaves it to our limit: the user is told the same either way.
    f = tmp_path / "deep.yaml"
    f.write_text(text)
    said = set()
    for loader in LOADERS:
        monkeypatch.setattr(safeio, "_YAML_LOADER", loader)
        with pytest.raises(HostileInputError) as found:
            parse_yaml_node(f)
        said.add(str(found.value))
    assert said == {f"{f}:{found.value.line}: YAML nested more than {MAX_YAML_DEPTH} levels deep; "
                    f"at most {MAX_YAML_DEPTH} are accepted"}


def test_nesting_up_to_the_limit_is_read(tmp_path: Path) -> None:
    f = tmp_path / "deep.yaml"
    f.write_text("[" * MAX_YAML_DEPTH + "]" * MAX_YAML_DEPTH)
    node = parse_yaml_node(f)
    for _ in range(MAX_YAML_DEPTH - 1):
        assert isinstance(node, yaml.SequenceNode)
        (node,) = node.value
    assert node.value == []


@pytest.mark.skipif(not hasattr(yaml, "CSafeLoader"), reason="PyYAML built without libyaml")
def test_libyaml_parses_where_present() -> None:
    from plugnproduce import safeio

    assert safeio._YAML_LOADER is yaml.CSafeLoader
