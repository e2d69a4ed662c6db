"""Issue 29: a derivation says what each node rests on in plain words and marks the reasons an answer is no."""

from __future__ import annotations

from plugnproduce import service

CELL = service.builtin("cells", "bin-picking.yaml")


def _nodes(node: dict) -> list[dict]:
    return [node, *(n for c in node["children"] for n in _nodes(c))]


def test_a_step_not_plausible_marks_its_problem_and_names_each_source() -> None:
    task = service.builtin("tasks", "bin-picking-invalid.yaml")
    tree = service.explain_plausible(task, CELL, 2).to_json()["derivation"]
    top = tree["children"]
    assert [n.get("fails", False) for n in top] == [True, False, False, False]
    assert top[0]["source"] == "rule" and top[0]["text"].startswith("device 'gripper' is not in a state")
    sources = {n["source"] for n in _nodes(tree)}
    assert sources <= {"finding", "rule", "ontology", "device chart", "process chart"}
    assert {"rule", "device chart", "process chart"} <= sources
    assert not any(n.get("fails") for c in top[1:] for n in _nodes(c))


def test_a_process_not_offered_marks_every_reason() -> None:
    tree = service.explain_offered(CELL, "transport").to_json()["derivation"]
    assert [(n["source"], n.get("fails")) for n in tree["children"]] == [("rule", True)]
    assert {n["source"] for n in tree["children"][0]["children"]} == {"ontology"}
