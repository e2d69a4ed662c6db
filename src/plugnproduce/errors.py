"""The project's exceptions: one base class, one subclass per kind of failure.

Findings (invalid, infeasible, implausible, non-conforming) are results, not
exceptions; these classes are for input that cannot be read and for failures of
the machinery itself.
"""

from __future__ import annotations

import re
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
