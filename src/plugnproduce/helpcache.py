"""``pnp --help`` from the user's cache folder: the text the command line printed last time, unchanged.

The top-level help lists every command, so printing it means importing the whole command line
(typer, click and every command module): ten times a bare interpreter's start. The text only
changes with the command line's code, the package's version and the width it is printed for,
so it is kept in the user's cache folder, named by those, and printed from there; a missing or
stale file is written again the next time the command line prints its help.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys

from plugnproduce.digests import sha256

TYPE_CHECKING = False  # typing itself is not imported: it costs a fifth of the start-up this module saves
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import TextIO

HELP = ["--help"]
"""The arguments whose answer is kept."""


def _width() -> int:
    """The columns the help is laid out for, found as ``shutil.get_terminal_size`` finds them."""
    with contextlib.suppress(ValueError):
        return int(os.environ.get("COLUMNS", ""))
    try:
        return os.get_terminal_size(sys.__stdout__.fileno()).columns if sys.__stdout__ else 80
    except (AttributeError, ValueError, OSError):
        return 80


def _cache_folder() -> str:
    """The user's cache folder, as :func:`plugnproduce.folders.cache_folder` names it.

    On Linux platformdirs names it from ``XDG_CACHE_HOME`` or ``~/.cache``; that rule is followed here
    without importing platformdirs, which imports ``pathlib`` and ``re`` and would double the start-up this
    module saves (``tests/test_folders.py`` holds the two to the same answer). Elsewhere, platformdirs answers.
    """
    if sys.platform.startswith("linux"):
        xdg = os.environ.get("XDG_CACHE_HOME", "")
        base = xdg if os.path.isabs(xdg) else os.path.expanduser("~/.cache")
        return os.path.join(base, "plugnproduce")
    import platformdirs

    return platformdirs.user_cache_dir("plugnproduce")


def help_file(folder: str | None = None) -> str:
    """The file of the help text for this command line's code, version, width and environment."""
    here = os.path.dirname(__file__)
    cli = os.path.join(here, "cli")
    h = sha256(f"{sys.version}\0{_width()}\0{sys.argv[0]}\0".encode())
    for name in ("NO_COLOR", "FORCE_COLOR", "TERM", "_TYPER_FORCE_DISABLE_TERMINAL", "LANG", "LC_ALL"):
        h.update(f"{name}={os.environ.get(name)}\0".encode())
    files = [os.path.join(cli, f) for f in os.listdir(cli) if f.endswith(".py")] + [os.path.join(here, "__init__.py")]
    for f in sorted(files):
        stat = os.stat(f)
        h.update(f"{os.path.basename(f)}\0{stat.st_size}\0{stat.st_mtime_ns}\0".encode())
    folder = folder or _cache_folder()
    return os.path.join(folder, f"help-{h.hexdigest()[:24]}.txt")


def print_kept(args: list[str]) -> bool:
    """Print the kept help for ``args`` and say so; False when there is none (or ``args`` ask for something else)."""
    if args != HELP:
        return False
    try:
        with open(help_file(), encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError):
        return False
    sys.stdout.write(text)
    sys.stdout.flush()
    return True


def keeping(args: list[str], main: Callable[[], None]) -> None:
    """Run ``main``; when it prints the help for :data:`HELP` and exits 0, keep what it printed."""
    if args != HELP:
        main()
        return
    real, copy = sys.stdout, io.StringIO()
    sys.stdout = _Tee(real, copy)
    try:
        main()
    except SystemExit as exc:
        if exc.code in (0, None):
            _keep(help_file(), copy.getvalue())
        raise
    finally:
        sys.stdout = real


class _Tee(io.TextIOBase):
    """Writes to the real standard output and to a copy."""

    def __init__(self, real: TextIO, copy: io.StringIO) -> None:
        self._real, self._copy = real, copy

    def write(self, text: str) -> int:
        self._copy.write(text)
        return self._real.write(text)

    def flush(self) -> None:
        self._real.flush()

    def isatty(self) -> bool:
        return self._real.isatty()

    def fileno(self) -> int:
        return self._real.fileno()

    @property
    def encoding(self) -> str:  # type: ignore[override]
        return self._real.encoding


def _keep(path: str, text: str) -> None:
    import tempfile

    with contextlib.suppress(OSError):  # a help that cannot be kept is printed again next time
        os.makedirs(os.path.dirname(path), exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".help-", dir=os.path.dirname(path))
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
