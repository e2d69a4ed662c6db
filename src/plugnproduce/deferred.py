"""Dataclasses whose methods are made on first use, so that a command does not pay for those it never uses.

Making a dataclass's methods (its ``__init__``, ``__eq__``, ``__repr__``, ``__hash__``, a frozen one's
``__setattr__``) compiles each from source when the class is declared. A warm ``pnp capabilities`` loads some
seventy dataclasses (the SCXML model, the descriptions, the reasoning's answers) and uses a few: making them all
cost about a fifth of its CPU time. :func:`dataclass` declares the class with stand-ins instead; the first use
makes the real methods, and from then on the class is exactly what :func:`dataclasses.dataclass` makes.
"""

from __future__ import annotations

from _thread import RLock
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar, dataclass_transform, overload

if TYPE_CHECKING:
    from dataclasses import Field, field
else:  # the field specifiers are read by type checkers alone: importing dataclasses imports inspect
    Field = field = None

T = TypeVar("T")


_MADE = RLock()
"""Held while a class's methods are made, so that two threads never make them twice."""
_DEFERRED: dict[type, dict[str, Any]] = {}
"""The classes whose dataclass methods are not made yet, with the options they were declared with."""


_AT_ONCE = False
"""Set by :func:`make_all_classes`: from then on a class of this package is made when it is declared."""


def make_all_classes() -> None:
    """Make every class of this package declared so far, and from then on each one as it is declared. A process
    that uses them from several threads (the HMI's server) calls this before its threads start: while :func:`_make`
    puts a class's methods in place of its stand-ins, the class briefly has neither, and another thread using it
    then would find ``object``'s (a module first imported by one of those threads declares its classes there)."""
    global _AT_ONCE  # noqa: PLW0603 - the process's one switch, set once
    with _MADE:
        _AT_ONCE = True
        for cls in [c for c in _DEFERRED if _ours(c)]:
            _make(cls)


def _ours(cls: type) -> bool:
    return cls.__module__.startswith("plugnproduce.")


def _make(cls: type) -> None:
    """Make the dataclass methods of ``cls`` now (its bases' first, as :func:`dataclasses.dataclass` reads them)."""
    with _MADE:
        options = _DEFERRED.pop(cls, None)
        if options is None:
            return
        for name in options.pop("_stand_ins"):
            delattr(cls, name)
        import dataclasses  # imports inspect: paid by the first class made, not by importing this module

        dataclasses.dataclass(cls, **options)


class _Fields:
    """A stand-in for ``__dataclass_fields__`` (and ``__match_args__``): asked for, it makes the class's methods,
    so that :func:`dataclasses.fields`, :func:`~dataclasses.replace`, :func:`~dataclasses.asdict` and a base's fields
    read by a subclass see the real thing."""

    def __init__(self, owner: type, name: str) -> None:
        self.owner, self.name = owner, name

    def __get__(self, instance: object, owner: type | None = None) -> Any:
        _make(self.owner)
        return self.owner.__dict__[self.name]


def _stand_in(owner: type, name: str) -> Callable[..., Any]:
    """A method that makes ``owner``'s methods, then calls the one it stood for."""

    def method(self: object, *args: Any, **kwargs: Any) -> Any:
        _make(owner)
        made = getattr(owner, name)  # the class's own, or what it inherits where the dataclass made none
        if made is None:  # __hash__ of eq without frozen: unhashable, as a dataclass is
            raise TypeError(f"unhashable type: {owner.__name__!r}")
        return made(self, *args, **kwargs)

    method.__name__ = method.__qualname__ = name
    return method


_METHODS = ("__init__", "__repr__", "__eq__", "__hash__")
_FROZEN = ("__setattr__", "__delattr__")
_ORDER = ("__lt__", "__le__", "__gt__", "__ge__")


@overload
def dataclass(cls: type[T], /) -> type[T]: ...


@overload
def dataclass(*, init: bool = ..., repr: bool = ..., eq: bool = ..., order: bool = ...,  # noqa: A002
              unsafe_hash: bool = ..., frozen: bool = ..., match_args: bool = ..., kw_only: bool = ...,
              slots: bool = ..., weakref_slot: bool = ...) -> Callable[[type[T]], type[T]]: ...


@dataclass_transform(field_specifiers=(Field, field))
def dataclass(cls: type[T] | None = None, /, **options: Any) -> Any:
    """:func:`dataclasses.dataclass` with the same options, its methods made when the class is first used.

    Until then the class holds stand-ins: calling a method, reading its fields
    (:func:`dataclasses.fields`, :func:`~dataclasses.replace`, :func:`~dataclasses.asdict`, a subclass's
    declaration) makes them, and from then on the class is exactly the dataclass. An instance read back by
    :mod:`pickle` needs none of them. ``slots=True`` makes a new class, so such a class is made at once. Type
    checkers see a dataclass (:func:`typing.dataclass_transform`). After :func:`make_all_classes`, a class of this
    package is made at once.
    """

    def wrap(c: type[T]) -> type[T]:
        if options.get("slots") or (_AT_ONCE and _ours(c)):
            import dataclasses

            return dataclasses.dataclass(c, **options)
        names = [*_METHODS, *(_FROZEN if options.get("frozen") else ()), *(_ORDER if options.get("order") else ())]
        own = [n for n in names if n not in c.__dict__]
        stand_ins = [*own, "__dataclass_fields__", *(() if "__match_args__" in c.__dict__ else ("__match_args__",))]
        for name in own:
            setattr(c, name, _stand_in(c, name))
        for name in stand_ins[len(own):]:
            setattr(c, name, _Fields(c, name))
        _DEFERRED[c] = {**options, "_stand_ins": stand_ins}
        return c

    return wrap if cls is None else wrap(cls)
