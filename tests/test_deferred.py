"""A dataclass whose methods are made on first use behaves as the dataclass it stands for, whatever is used first."""

from __future__ import annotations

import copy
import dataclasses
import pickle
import sys
import threading
import types

import pytest

from plugnproduce.deferred import dataclass

# The classes are declared inside each test, so that each test sees them before any method is made.


def _node_classes() -> tuple[type, type]:
    @dataclass(kw_only=True)
    class Node:
        line: int | None = dataclasses.field(default=None, compare=False, repr=False)
        extra: dict[str, str] = dataclasses.field(default_factory=dict)

    @dataclass(kw_only=True)
    class Data(Node):
        id: str
        src: str | None = None

    return Node, Data


def _frozen_class() -> type:
    @dataclass(frozen=True)
    class Point:
        x: int
        tags: tuple[str, ...] = ()

        def moved(self) -> Point:
            return dataclasses.replace(self, x=self.x + 1)

    return Point


def test_a_subclass_made_first_takes_its_base_s_fields() -> None:
    _, data_class = _node_classes()
    d = data_class(id="a", line=3)
    assert [f.name for f in dataclasses.fields(d)] == ["line", "extra", "id", "src"]
    assert d == data_class(id="a", line=99)  # line is not compared
    assert d != data_class(id="b")
    with pytest.raises(TypeError, match="unhashable type: 'Data'"):
        hash(d)
    with pytest.raises(TypeError, match="id"):
        data_class()  # a required field left out


def test_repr_names_the_compared_fields_as_a_dataclass_does() -> None:
    _, data_class = _node_classes()
    assert repr(data_class(id="a", src="s", line=1)).endswith("Data(extra={}, id='a', src='s')")


def test_a_frozen_class_is_immutable_hashable_and_replaceable() -> None:
    point = _frozen_class()
    p = point(1, ("t",))
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.x = 2
    assert hash(p) == hash(point(1, ("t",))) and p.moved() == point(2, ("t",))
    assert dataclasses.asdict(p) == {"x": 1, "tags": ("t",)}


@dataclass(frozen=True)
class Kept:
    """Used by one test only, which reads instances back before any method of the class is made."""

    x: int
    tags: tuple[str, ...] = ()


def test_an_instance_read_back_before_any_method_was_made_compares_and_converts() -> None:
    """An instance unpickled (as the warm commands read the kept knowledge) is made without ``__init__``: the
    first comparison, field list or conversion makes the methods then."""
    kept = Kept.__new__(Kept)
    kept.__dict__.update(x=5, tags=("t",))  # as pickle builds an instance
    read = pickle.loads(pickle.dumps(kept))
    assert "__dataclass_params__" not in Kept.__dict__  # nothing made so far
    assert dataclasses.is_dataclass(read)
    assert dataclasses.astuple(read) == (5, ("t",))  # type: ignore[arg-type]
    assert read == Kept(5, ("t",)) and read != Kept(6) and copy.deepcopy(read) == read and hash(read) == hash(kept)


def test_fields_of_a_class_not_made_yet_are_its_declared_fields() -> None:
    node, data_class = _node_classes()
    assert [f.name for f in dataclasses.fields(data_class)] == ["line", "extra", "id", "src"]
    assert [f.name for f in dataclasses.fields(node)] == ["line", "extra"]
    assert data_class.__match_args__ == ()  # type: ignore[attr-defined]  # kw_only: no positional pattern


def test_methods_the_class_writes_itself_are_kept() -> None:
    @dataclass(frozen=True)
    class Named:
        name: str
        detail: str

        def __hash__(self) -> int:
            return hash(self.name)

        def __repr__(self) -> str:
            return f"<{self.name}>"

    n = Named("a", "b")
    assert hash(n) == hash("a") and repr(n) == "<a>" and n != Named("a", "c")


def test_order_and_eq_off_follow_the_options() -> None:
    @dataclass(order=True, frozen=True)
    class Version:
        major: int
        minor: int

    @dataclass(eq=False)
    class Handle:
        value: int

    assert sorted([Version(1, 2), Version(0, 9)]) == [Version(0, 9), Version(1, 2)]
    h = Handle(1)
    assert h != Handle(1) and hash(h) == hash(h)  # identity, as a dataclass with eq=False


def test_two_threads_making_the_same_class_make_it_once() -> None:
    point = _frozen_class()
    errors: list[BaseException] = []

    def use() -> None:
        try:
            assert point(1) == point(1)
        except BaseException as exc:  # noqa: BLE001 - reported by the assertion below
            errors.append(exc)

    threads = [threading.Thread(target=use) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert errors == [] and point.__dataclass_params__.frozen  # type: ignore[attr-defined]


def test_make_all_classes_makes_every_class_of_the_package_before_threads_use_them() -> None:
    from plugnproduce import service
    from plugnproduce.description.model import DeviceDescription
    from plugnproduce.statechart.model import Transition

    point = _frozen_class()  # a class of the user's own: left to be made when it is first used
    service.make_all_classes()
    for cls in (DeviceDescription, Transition):  # the real dataclass methods in place, no stand-in left to swap
        assert isinstance(cls.__dict__["__dataclass_fields__"], dict)
        assert cls.__dict__["__init__"].__qualname__ == f"{cls.__qualname__}.__init__"
    assert "__dataclass_params__" not in point.__dict__


def test_a_class_of_the_package_declared_after_make_all_classes_is_made_at_once(monkeypatch: pytest.MonkeyPatch) -> None:
    from plugnproduce import service

    service.make_all_classes()
    module = types.ModuleType("plugnproduce.late")  # a module first imported by one of the server's threads
    monkeypatch.setitem(sys.modules, module.__name__, module)
    module.dataclass = dataclass  # type: ignore[attr-defined]
    exec("@dataclass(frozen=True)\nclass Late:\n    x: int\n", module.__dict__)  # noqa: S102 - a fixed declaration
    late = module.Late  # type: ignore[attr-defined]
    assert isinstance(late.__dict__["__dataclass_fields__"], dict)  # no stand-in for another thread to find gone
    assert late(1) == late(1) and repr(late(2)) == "Late(x=2)"
    user = _frozen_class()  # the user's own classes are still made on their first use
    assert "__dataclass_params__" not in user.__dict__
