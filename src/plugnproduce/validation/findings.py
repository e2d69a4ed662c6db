"""Problems found in descriptions, and the report that gathers them."""

from __future__ import annotations

from dataclasses import dataclass, field

from plugnproduce.errors import MAX_MESSAGE, DescriptionError, UnreadableError, tidy


@dataclass(frozen=True, order=True)
class Finding:
    """One problem: where it is and what is wrong (what was found, what was expected)."""

    file: str
    line: int
    message: str
    unreadable: bool = False
    """The file could not be read at all (malformed or hostile), rather than being invalid."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "message", tidy(self.message, MAX_MESSAGE))  # one line, short quotes of the input

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.message}" if self.line else f"{self.file}: {self.message}"

    @classmethod
    def from_error(cls, exc: DescriptionError) -> Finding:
        """The problem a description error reports."""
        return cls(exc.file or "<input>", exc.line or 0, exc.message, isinstance(exc, UnreadableError))

    def to_json(self) -> dict[str, object]:
        """A plain dict for ``--json``."""
        return {"file": self.file, "line": self.line or None, "message": self.message, "unreadable": self.unreadable}


@dataclass
class Report:
    """What validation found, and what it looked at."""

    problems: list[Finding] = field(default_factory=list)
    files: list[str] = field(default_factory=list)

    @property
    def valid(self) -> bool:
        """No problem at all."""
        return not self.problems

    @property
    def unreadable(self) -> bool:
        """Some input could not be read (malformed or hostile)."""
        return any(p.unreadable for p in self.problems)

    def add(self, problem: Finding) -> None:
        """Record a problem once."""
        if problem not in self.problems:
            self.problems.append(problem)

    def sorted(self) -> list[Finding]:
        """The problems by file and line."""
        return sorted(self.problems)
