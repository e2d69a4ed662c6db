"""Reading a child process's output line by line, never waiting without a bound."""

from __future__ import annotations

import queue
import threading
from typing import IO

WAIT = 60.0
"""Seconds a test waits for a line before it fails (generous: the machine may be fully loaded)."""


class Lines:
    """The lines of a text pipe, read by a thread; :meth:`next` fails the test instead of hanging."""

    def __init__(self, pipe: IO[str] | None) -> None:
        if pipe is None:
            raise ValueError("the process was started without stdout=PIPE")
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._thread = threading.Thread(target=self._read, args=(pipe,), daemon=True)
        self._thread.start()

    def _read(self, pipe: IO[str]) -> None:
        for line in pipe:
            self._lines.put(line)
        self._lines.put(None)

    def next(self, timeout: float = WAIT) -> str:
        """The next line; AssertionError if none comes within ``timeout`` seconds or the pipe ends."""
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError(f"no line within {timeout:g} s") from None
        if line is None:
            raise AssertionError("the process closed its output before the line came")
        return line

    def rest(self, timeout: float = WAIT) -> list[str]:
        """Every line until the pipe ends (the process has exited); AssertionError if it does not end in time."""
        self._thread.join(timeout)
        if self._thread.is_alive():
            raise AssertionError(f"the output did not end within {timeout:g} s")
        lines = []
        while (line := self._lines.get_nowait()) is not None:
            lines.append(line)
        return lines
