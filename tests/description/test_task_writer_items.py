"""The task writer writes each step's item once per process (a long task's repairs repeat almost all of its
steps): the text is exactly what writing the whole document at once gives, whatever the values hold."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from plugnproduce.description import taskfile
from plugnproduce.description.model import Step, Task

ODD = st.text(st.sampled_from(["a", "Z", "0", " ", "-", ":", "#", "'", '"', "\n", "\t", "\x85", "\u2028", "ä",
                               "漢", "\U0002f800", "[", "{", "&", "*", "!", "|", ">", "%", "@", "`", "\r"]),
              max_size=90)
VALUES = st.one_of(ODD, st.integers(-10**20, 10**20), st.floats(allow_nan=False), st.booleans(), st.none(),
                   st.lists(st.floats(-1e3, 1e3), max_size=6))
STEPS = st.lists(st.builds(lambda c, b, p, n: (c, b, p, n), st.sampled_from(["pick", "place", "x y", "- z"]),
                           st.dictionaries(ODD, ODD, max_size=2), st.dictionaries(ODD, VALUES, max_size=3),
                           st.one_of(st.none(), st.from_regex(r"[a-z][a-z0-9_]{0,8}", fullmatch=True))),
                 min_size=1, max_size=12)


def whole(task: Task, block: bool) -> str:
    """The task written as one document, as the writer wrote it before it kept its items."""
    doc: dict[str, object] = {"task": task.name}
    if task.description:
        doc["description"] = task.description
    if task.repeat != 1:
        doc["repeat"] = task.repeat
    return taskfile._dump({**doc, "steps": taskfile.task_entries(task)}, block)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(name=ODD, description=ODD, steps=STEPS, block=st.booleans())
def test_a_task_is_written_as_one_document_would_be(name: str, description: str, steps: list, block: bool) -> None:
    task = Task(name, tuple(Step(i, c, b, p, name=n) for i, (c, b, p, n) in enumerate(steps, start=1)), "t.yaml",
                description)
    expected = whole(task, block)
    assert taskfile.task_to_yaml(task, block) == expected  # items new to the process
    assert taskfile.task_to_yaml(task, block) == expected  # items written before


def test_a_long_tasks_repeated_steps_are_written_once() -> None:
    steps = tuple(Step(i, "place", {}, {"speed": 10 + i % 7}) if i % 2 else Step(i, "bin-pick") for i in range(1, 2001))
    task = Task("long", steps, "long.yaml")
    taskfile._ITEM_TEXT.clear()
    assert taskfile.task_to_yaml(task) == whole(task, False)
    assert len(taskfile._ITEM_TEXT) == 8  # bin-pick, and place with each of its 7 speeds
