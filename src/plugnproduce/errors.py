"""The project's exceptions: one base class, one subclass per kind of failure.

Findings (invalid, infeasible, implausible, non-conforming) are results, not
exceptions; these classes are for input that cannot be read and for failures of
the machinery itself.
"""

from __future__ import annotations

from pathlib import Path


class PlugNProduceError(Exception):
    """Base class of every error the project raises on purpose."""


class DescriptionError(PlugNProduceError):
    """A description (or task, cell, chart) that cannot be read: says what, and where."""

    def __init__(self, message: str, file: str | Path | None = None, line: int | None = None):
        self.message = message
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
