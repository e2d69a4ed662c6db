"""Where the interpreter's time comes from: a monotonic clock, or a manual one for tests."""

from __future__ import annotations

import time
from typing import Protocol


class Clock(Protocol):
    """A source of time in seconds; only differences matter."""

    def time(self) -> float:
        """The current time in seconds."""


class MonotonicClock:
    """Real time from :func:`time.monotonic` (the same clock asyncio's loop uses)."""

    def time(self) -> float:
        """The current monotonic time in seconds."""
        return time.monotonic()


class ManualClock:
    """Time that moves only when told to: delayed sends are tested without sleeping."""

    def __init__(self, start: float = 0.0):
        self._now = start

    def time(self) -> float:
        """The current (manual) time in seconds."""
        return self._now

    def advance(self, seconds: float) -> None:
        """Move time forward by ``seconds`` (not backwards)."""
        if seconds < 0:
            raise ValueError(f"cannot move time backwards (by {seconds} s)")
        self._now += seconds

    def advance_to(self, moment: float) -> None:
        """Move time forward to ``moment`` (no change if it has passed)."""
        self._now = max(self._now, moment)
