"""The project's exceptions: one base class, one subclass per kind of failure.

Findings (invalid, infeasible, implausible, non-conforming) are results, not
exceptions; these classes are for input that cannot be read and for failures of
the machinery itself.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable
from pathlib import Path

MAX_EXCERPT = 60
"""Most characters of the input an error message quotes in one piece."""

MAX_MESSAGE = 600
"""Longest message a description error carries (its file and line come on top)."""

_QUOTED = re.compile(r"(?<![A-Za-z])'[^']*'|\"[^\"]*\"")  # an apostrophe inside a word (device's) opens none

_LONG_WORD = re.compile(rf"\S{{{MAX_EXCERPT + 1},}}")


def excerpt(text: str, limit: int = MAX_EXCERPT) -> str:
    """``text`` on one line and at most about ``limit`` characters: its start and end around an ellipsis."""
    text = " ".join(str(text).split())
    if len(text) <= limit:
        return text
    half = max(limit // 2 - 1, 1)
    return f"{text[:half]}…{text[-half:]}"


def tidy(message: str, limit: int = 300) -> str:
    """A library's error message made fit for a ``file:line: message`` line.

    One line; every quoted value cut to a short excerpt; at most ``limit`` characters. Parsers
    quote what they could not read, and what they read is the input, which a message must not
    repeat at length.
    """
    text = " ".join(str(message).split())
    text = _QUOTED.sub(lambda m: m.group()[0] + excerpt(m.group()[1:-1]) + m.group()[-1], text)
    return excerpt(text, limit)


def shorten_words(text: str, limit: int = MAX_EXCERPT) -> str:
    """``text`` with every run of more than ``limit`` non-blank characters cut to an :func:`excerpt`.

    For messages of parsers that name what they read without quoting it (lxml's tag names).
    """
    return _LONG_WORD.sub(lambda m: excerpt(m.group(), limit), str(text))


class PlugNProduceError(Exception):
    """Base class of every error the project raises on purpose."""


MAX_KNOWN = 12
"""Most known names an :class:`UnknownName` message lists when none is close to the one given."""


class UnknownName(PlugNProduceError, KeyError):
    """A name the user gave that names nothing known: a device, process command, role, state, parameter, run...

    Carries what kind of name it is (``kind``), the name, where it was looked up (``owner``: ``device
    gripper``), the known names and the nearest of them, for a "did you mean" in the message. It is a
    :class:`KeyError` too, so that code asking "is it there?" by catching one goes on working; the faces
    map it to bad input (exit 2, HTTP 404), and any other ``KeyError`` to a bug.
    """

    def __init__(self, kind: str, name: object, known: Iterable[object] = (), owner: str | None = None,
                 detail: str | None = None):
        self.kind, self.name, self.owner, self.detail = kind, name, owner, detail
        self.known = tuple(sorted({str(k) for k in known}))
        self.close = tuple(difflib.get_close_matches(str(name), self.known, n=2)) if isinstance(name, str) else ()
        super().__init__(self.message())

    def message(self) -> str:
        """``unknown state 'Opne' of device gripper; did you mean Open?`` (or the known names, or ``detail``)."""
        name = repr(excerpt(self.name)) if isinstance(self.name, str) else str(self.name)
        text = f"unknown {self.kind} {name}" + (f" of {self.owner}" if self.owner else "")
        if self.detail is not None:
            return f"{text}; {self.detail}"
        if self.close:
            return f"{text}; did you mean {' or '.join(self.close)}?"
        if not self.known:
            return text
        more = f", … ({len(self.known)} in all)" if len(self.known) > MAX_KNOWN else ""
        return f"{text} (known: {', '.join(self.known[:MAX_KNOWN])}{more})"

    def __str__(self) -> str:  # a KeyError's str() is the repr of its argument
        return self.message()

    def __reduce__(self) -> tuple[type[UnknownName], tuple[str, object, tuple[str, ...], str | None, str | None]]:
        # raised in an HMI worker process and re-raised in the server: rebuilt from its fields, not its message
        return UnknownName, (self.kind, self.name, self.known, self.owner, self.detail)


def bug_message(exc: BaseException, traceback_at: str) -> str:
    """The one line a face shows for an exception that is none of the family's: a bug, not the user's mistake.

    ``traceback_at`` says where the traceback went (a log file, the server's log)."""
    what = tidy(f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__, 200)
    return (f"error: a bug in plugnproduce, not a mistake in the input ({what}); the traceback is in "
            f"{traceback_at}: please report it with that traceback")


class DescriptionError(PlugNProduceError):
    """A description (or task, cell, chart) that cannot be read: says what, and where."""

    def __init__(self, message: str, file: str | Path | None = None, line: int | None = None):
        self.message = tidy(message, MAX_MESSAGE)  # one line, and what it quotes of the input kept short
        self.file = str(file) if file is not None else None
        self.line = line
        super().__init__(self.location_message())

    def location_message(self) -> str:
        """The one-line ``file:line: message`` form used by every interface."""
        if self.file is None:
            return self.message
        if self.line is None:
            return f"{self.file}: {self.message}"
        return f"{self.file}:{self.line}: {self.message}"


class QuantityError(DescriptionError):
    """A quantity a task writes that is no finite number, as written or once in its parameter's unit (``1e308 kN``
    is 1e311 N): bad input, refused at its line, never turned into a figure."""


class UnreadableError(DescriptionError):
    """Input that cannot be parsed at all: malformed XML, Turtle or YAML, or an unreadable file."""


class HostileInputError(UnreadableError):
    """Input refused for safety: a DOCTYPE, entities, an oversized or too deep document."""


class OntologyError(PlugNProduceError):
    """The ontology cannot be loaded or is inconsistent."""


class EncodingError(PlugNProduceError):
    """An ASP encoding or the facts built for it are broken (a bug, not bad input)."""


class ExecutionError(PlugNProduceError):
    """A state chart could not be executed."""


class ProtocolError(PlugNProduceError):
    """Talking to a device failed."""


class ProtocolTimeout(ProtocolError):
    """A device did not answer in time."""


class ProtocolConnectionError(ProtocolError):
    """The connection to a device could not be made or was lost."""


class RemoteError(ProtocolError):
    """A device answered with an error."""
