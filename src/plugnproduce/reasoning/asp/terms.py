"""The one typed boundary between Python and ASP: every predicate the encodings read or write.

Each predicate is an immutable value class (as a frozen dataclass, cheaper to make) whose fields
are ``str`` (an ASP string: an IRI, an id, a name), ``int`` (an ASP number) or
:class:`clingo.Symbol` (a nested term, e.g. a binding list). Facts become ASP text through
:func:`program`; a model's symbols become typed atoms through :func:`decode`. Nothing else in
the package builds or reads ASP atoms, so a misspelt predicate or a wrong argument type fails
here, loudly.
"""

from __future__ import annotations

import dataclasses
import operator
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from typing import Any, ClassVar, TypeVar, cast, dataclass_transform

import clingo

from plugnproduce.errors import EncodingError

A = TypeVar("A", bound="Atom")

_REGISTRY: dict[tuple[str, int], type[Atom]] = {}


class Atom:
    """Base class of the typed predicates; subclasses are made by :func:`predicate`."""

    __slots__ = ()
    asp: ClassVar[str]
    _fields: ClassVar[tuple[str, ...]]
    _values: ClassVar[Callable[[Any], tuple[Any, ...]]]
    _encoders: ClassVar[tuple[Callable[[Any], str], ...]]
    _decoders: ClassVar[tuple[Callable[[clingo.Symbol], Any], ...]]

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return bool(self.__class__._values(self) == self.__class__._values(other))

    def __hash__(self) -> int:
        return hash(self.__class__._values(self))

    def __repr__(self) -> str:
        args = ", ".join(f"{n}={v!r}" for n, v in zip(self._fields, self.__class__._values(self), strict=True))
        return f"{self.__class__.__qualname__}({args})"

    def __setattr__(self, name: str, value: object) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[type[Atom], tuple[Any, ...]]:
        return self.__class__, self.__class__._values(self)

    def text(self) -> str:
        """The atom in ASP syntax, e.g. ``has_skill("gripper","http://...#CanGrip")``."""
        if not self._fields:
            return self.asp
        args = ",".join(enc(getattr(self, f)) for enc, f in zip(self._encoders, self._fields, strict=True))
        return f"{self.asp}({args})"

    @classmethod
    def from_symbol(cls: type[A], symbol: clingo.Symbol) -> A:
        """The typed atom a clingo symbol stands for."""
        args = symbol.arguments
        if symbol.name != cls.asp or len(args) != len(cls._decoders):
            raise EncodingError(f"expected {cls.asp}/{len(cls._decoders)}; found {symbol}")
        return cls._of(symbol, args)

    @classmethod
    def _of(cls: type[A], symbol: clingo.Symbol, args: Sequence[clingo.Symbol]) -> A:
        """The typed atom of a symbol of this predicate and its arguments (read once by the caller)."""
        try:
            return cls(*(dec(a) for dec, a in zip(cls._decoders, args, strict=True)))
        except (RuntimeError, TypeError) as exc:
            raise EncodingError(f"{symbol} does not fit {cls.__name__}") from exc


def quote(value: str) -> str:
    """An ASP string literal."""
    return '"' + value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _number(value: int) -> str:
    if not isinstance(value, int) or isinstance(value, bool):
        raise EncodingError(f"expected a whole number for an ASP number; found {value!r}")
    return str(value)


def _symbol_text(value: clingo.Symbol) -> str:
    return str(value)


_CODECS: dict[object, tuple[Callable[[Any], str], Callable[[clingo.Symbol], Any]]] = {
    "str": (quote, lambda s: s.string),
    "int": (_number, lambda s: s.number),
    "clingo.Symbol": (_symbol_text, lambda s: s),
}
_CODECS.update({str: _CODECS["str"], int: _CODECS["int"], clingo.Symbol: _CODECS["clingo.Symbol"]})


def codec(type_name: str, encode: Callable[[Any], str], decode: Callable[[clingo.Symbol], Any]) -> None:
    """Let a predicate's field be of the type named ``type_name`` (as annotated): written by ``encode``, read by
    ``decode`` (which raises :class:`EncodingError` for a symbol that does not fit)."""
    _CODECS[type_name] = (encode, decode)


def _init(names: tuple[str, ...]) -> Callable[..., None]:
    """The ``__init__`` of a predicate with fields ``names``: positional or by name, as a dataclass's."""
    params = "".join(f", {n}" for n in names)
    body = "".join(f"\n    _set(self, {n!r}, {n})" for n in names) or "\n    pass"
    scope: dict[str, Any] = {"_set": object.__setattr__}
    exec(f"def __init__(self{params}) -> None:{body}", scope)  # noqa: S102 - our own field names, checked below
    return scope["__init__"]  # type: ignore[no-any-return]


def _first_init(owner: type[Atom], names: tuple[str, ...]) -> Callable[..., None]:
    """A stand-in ``__init__`` that compiles the predicate's own (:func:`_init`) when it is first called: a command
    declares some seventy predicates and makes atoms of a few."""

    def __init__(self: Atom, *args: Any, **kwargs: Any) -> None:
        if owner.__dict__["__init__"] is __init__:
            owner.__init__ = _init(names)  # type: ignore[method-assign]
        owner.__init__(self, *args, **kwargs)

    return __init__


def _values(names: tuple[str, ...]) -> Callable[[Any], tuple[Any, ...]]:
    if len(names) > 1:
        return operator.attrgetter(*names)
    if names:
        one = operator.attrgetter(names[0])
        return lambda atom: (one(atom),)
    return lambda atom: ()


@dataclass_transform(frozen_default=True)
def predicate(name: str) -> Callable[[type[A]], type[A]]:
    """Class decorator: make a class of annotated fields a typed ASP predicate called ``name``: immutable, equal by
    value, with a ``__slots__`` per field and ``__match_args__`` (what a frozen dataclass gives; built here at a
    tenth of its cost, for the import of the predicates is paid by every command that reasons)."""

    def wrap(cls: type[A]) -> type[A]:
        annotations = cls.__dict__.get("__annotations__", {})
        names = tuple(n for n, t in annotations.items() if not str(t).startswith(("ClassVar", "typing.ClassVar")))
        if not all(n.isidentifier() and not n.startswith("_") for n in names):
            raise EncodingError(f"predicate {name}: a field name must be a plain identifier")
        try:
            codecs = [_CODECS[annotations[n]] for n in names]
        except KeyError as exc:
            raise EncodingError(f"predicate {name}: unsupported field type {exc.args[0]!r}") from exc
        namespace = {k: v for k, v in cls.__dict__.items() if k not in ("__dict__", "__weakref__")}
        namespace.update(__slots__=names, __match_args__=names, _fields=names,
                         _values=staticmethod(_values(names)), asp=name,
                         _encoders=tuple(c[0] for c in codecs), _decoders=tuple(c[1] for c in codecs))
        data = cast("type[A]", type(cls.__name__, cls.__bases__, namespace))
        data.__init__ = _first_init(data, names)  # type: ignore[method-assign]
        key = (name, len(names))
        if key in _REGISTRY:
            raise EncodingError(f"predicate {name}/{len(names)} declared twice")
        _REGISTRY[key] = data
        return data

    return wrap


def program(atoms: Iterable[Atom]) -> str:
    """ASP text stating every atom as a fact."""
    return "".join(a.text() + ".\n" for a in atoms)


class Model:
    """The typed atoms of one answer set, by predicate class; each predicate's atoms are decoded when first asked
    for (a long task's check shows an ``at/5`` atom per step and device, which not every reader needs)."""

    def __init__(self, atoms: dict[type[Atom], list[Atom]], cost: Sequence[int] = (),
                 shown: dict[type[Atom], list[tuple[clingo.Symbol, Sequence[clingo.Symbol]]]] | None = None):
        self._atoms = atoms
        self._shown = shown or {}
        self.cost = tuple(cost)

    def __getitem__(self, cls: type[A]) -> list[A]:
        if cls not in self._atoms and cls in self._shown:
            self._atoms[cls] = [cls._of(symbol, args) for symbol, args in self._shown.pop(cls)]
        return self._atoms.get(cls, [])  # type: ignore[return-value]


def decode(symbols: Iterable[clingo.Symbol], cost: Sequence[int] = ()) -> Model:
    """Sort a model's symbols by typed predicate; a shown atom of no known predicate is an error."""
    shown: dict[type[Atom], list[tuple[clingo.Symbol, Sequence[clingo.Symbol]]]] = defaultdict(list)
    for s in symbols:
        args = s.arguments
        cls = _REGISTRY.get((s.name, len(args)))
        if cls is None:
            raise EncodingError(f"the encodings show {s.name}/{len(args)}, which no typed predicate declares")
        shown[cls].append((s, args))
    return Model({}, cost, dict(shown))


def strings(term: clingo.Symbol) -> list[str]:
    """The strings of a cons list ``("a",("b",nil))``, first element first."""
    out: list[str] = []
    while term.type == clingo.SymbolType.Function and len(term.arguments) == 2:
        out.append(term.arguments[0].string)
        term = term.arguments[1]
    return out
