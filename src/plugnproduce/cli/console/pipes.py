"""Standard output that outlives its reader: ``pnp report RUN | head`` ends quietly, with the command's own exit code.

When the reader of a pipe goes away (``head`` has read its lines), writing raises
``BrokenPipeError``. A command should neither report that as an error nor let it decide
the exit code: an implausible ``pnp check`` piped to ``head`` still exits 1. So from the
first broken write on, standard output is pointed at the null device and the command
carries on to its natural end.
"""

from __future__ import annotations

import os
import sys
from typing import Any, TextIO


class QuietPipe:
    """A text stream wrapper that swallows the first ``BrokenPipeError`` and discards all later output."""

    def __init__(self, stream: TextIO):
        self._stream = stream
        self.closed_by_reader = False

    def write(self, text: str) -> int:
        """Write ``text``; once the reader has gone, pretend to."""
        if not self.closed_by_reader:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self._reader_gone()
        return len(text)

    def flush(self) -> None:
        """Flush, unless the reader has gone."""
        if not self.closed_by_reader:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._reader_gone()

    def _reader_gone(self) -> None:
        self.closed_by_reader = True
        try:  # what is still buffered (and the interpreter's last flush) goes nowhere instead of failing
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self._stream.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass  # not a file descriptor (a test's buffer): dropping our own writes is enough

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def tolerate_closed_stdout() -> None:
    """Make ``sys.stdout`` a :class:`QuietPipe` (once), so a closed pipe ends output, not the command."""
    if not isinstance(sys.stdout, QuietPipe):
        sys.stdout = QuietPipe(sys.stdout)
