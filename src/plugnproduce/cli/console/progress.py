"""What a long command is doing, as progress on a terminal: a spinner with the current phase on stderr.

Only when stderr is a terminal, and never with ``--json``: piped or redirected output gets
nothing extra. Each finished phase stays as one line (``✓ discovering devices … 1.1 s``).
"""

from __future__ import annotations

import sys
import time
from types import TracebackType
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # rich is imported when progress is really shown: start-up stays light
    from rich.console import Console
    from rich.live import Live


def on_a_terminal(json_out: bool = False) -> bool:
    """Whether progress should be shown: stderr is a terminal and the output is not for a machine."""
    return not json_out and sys.stderr.isatty()


class Phases:
    """Shows one phase at a time with a spinner; call it with each new phase's text, :meth:`close` at the end.

    When ``enabled`` is false every call does nothing. ``console`` defaults to stderr.
    """

    def __init__(self, enabled: bool, console: Console | None = None):
        self.enabled = enabled
        self._console = console
        self._live: Live | None = None
        self._phase: str | None = None
        self._since = 0.0

    def __call__(self, phase: str) -> None:
        """Begin ``phase``: the one before it is shown as done."""
        if not self.enabled:
            return
        from rich.live import Live
        from rich.spinner import Spinner

        self._finish()
        self._phase, self._since = phase, time.monotonic()
        spinner = Spinner("dots", f"{phase} …")
        if self._live is None:  # the journal's lines may share the terminal: keep the spinner below them
            self._live = Live(spinner, console=self.console, transient=True, refresh_per_second=10,
                              redirect_stdout=sys.stdout.isatty(), redirect_stderr=False)
            self._live.start()
        else:
            self._live.update(spinner)

    def update(self, text: str) -> None:
        """Change what the current phase says (e.g. the step being run), without ending it."""
        if self.enabled and self._live is not None and self._phase is not None:
            from rich.spinner import Spinner

            self._live.update(Spinner("dots", f"{self._phase}: {text}"))

    def echo(self, line: str) -> None:
        """Print ``line`` on stdout; on a terminal the spinner is cleared first and drawn again below it, so that
        the two never run together on one line."""
        if self._live is None or not sys.stdout.isatty():
            print(line, flush=True)
            return
        self._live.stop()  # transient: the spinner's line is erased
        print(line, flush=True)
        self._live.start(refresh=True)

    @property
    def console(self) -> Console:
        """Where progress goes: the given console, else stderr."""
        if self._console is None:
            from rich.console import Console

            self._console = Console(stderr=True)
        return self._console

    def _finish(self) -> None:
        if self._phase is not None:
            self.console.print(f"[green]✓[/] {self._phase} [dim]{time.monotonic() - self._since:.1f} s[/]",
                               highlight=False)
            self._phase = None

    def close(self, last_done: bool = False) -> None:
        """Stop the spinner; with ``last_done`` the current phase is shown as done, else it just disappears."""
        if not self.enabled:
            return
        if last_done:
            self._finish()
        if self._live is not None:
            self._live.stop()
            self._live = None

    def __enter__(self) -> Phases:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()
