"""Where a description rests: every object read from a file remembers the file and line it came from,
so that a finding can say where it is."""

from __future__ import annotations

from plugnproduce.deferred import dataclass


@dataclass(frozen=True)
class Where:
    """A place in a description file."""

    file: str
    line: int | None = None

    def __str__(self) -> str:
        return self.file if self.line is None else f"{self.file}:{self.line}"
