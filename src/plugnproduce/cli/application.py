"""The typer application, its error boundary and output helpers shared by all commands."""

from __future__ import annotations

import importlib
import json
import logging
import os
import sys
from collections.abc import Callable
from functools import wraps
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn, TypeVar

import typer

from plugnproduce.cli.console.helptext import PlainTyper
from plugnproduce.errors import DescriptionError, PlugNProduceError, bug_message

if TYPE_CHECKING:  # the knowledge is loaded by the commands that need it
    from plugnproduce.service import Knowledge

app = PlainTyper(
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain help: no "<bool>" after flags, no boxes
    help="Plug'n'Produce cell controller: from device and process descriptions to executable SCXML.",
)

F = TypeVar("F", bound=Callable[..., Any])

LIBRARIES: dict[str, Any] = {"folders": [], "builtin": True}
"""The libraries every command loads: ``--library`` options, then ``PNP_LIBRARY``; see :func:`knowledge`."""


def knowledge(cell: str | Path | None = None) -> Knowledge:
    """The knowledge the command line's libraries give (plus those a cell file lists), a service argument."""
    from plugnproduce import service

    k = service.knowledge(tuple(LIBRARIES["folders"]), builtin=LIBRARIES["builtin"])
    return service.knowledge_for_cell(cell, k) if cell is not None else k


JSON_OPTION = typer.Option(False, "--json", help="Machine-readable output.")
DISCOVERY_OPTION = typer.Option(None, "--discovery-timeout", metavar="SECONDS", min=0.1, max=3600,
                                help="Most seconds to wait for the cell's devices on the network (default 10; "
                                     "60 for simulated devices). The wait ends as soon as all have answered.")
INTERFACE_OPTION = typer.Option(None, "--interface", metavar="NAME|ADDRESS",
                                help="The network interface the devices are on: a name (eth0) or one of this "
                                     "machine's IPv4 addresses (default: PNP_INTERFACE, else loopback).")


def interface_address(interface: str | None) -> str:
    """The address ``--interface`` (else ``PNP_INTERFACE``, else loopback) names; an unknown one is exit 2, said
    before anything is loaded."""
    from plugnproduce.controller import chosen_address

    return chosen_address(interface)


QUIET_LOGGERS = ("rdflib.term",)
"""Libraries' loggers the command line (and the HMI it serves) hears only from at ERROR."""


def quiet_library_chatter() -> None:
    """Silence the warnings rdflib logs, unasked, for every odd IRI or literal it builds.

    What matters of them is reported as a finding with its file and line; the warnings would
    reach the user's terminal as lines of their own. Configuring logging is the application's
    part, so this is done here, at the command line's start, not where the library reads Turtle.
    """
    for name in QUIET_LOGGERS:
        logging.getLogger(name).setLevel(logging.ERROR)


def _print_version(wanted: bool) -> None:
    if wanted:
        from plugnproduce import __version__

        typer.echo(f"pnp (plugnproduce) {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: bool = typer.Option(False, "--version", is_eager=True, callback=_print_version,
                                 help="Print the version and exit."),
    library: list[str] = typer.Option([], "--library", metavar="DIR",
                                      help="A library folder (ontology/, devices/, processes/, cells/, tasks/); "
                                           "repeatable. PNP_LIBRARY adds folders separated by ':'."),
    no_builtin: bool = typer.Option(False, "--no-builtin", help="Leave the built-in library out."),
) -> None:
    """Plug'n'Produce cell controller: from device and process descriptions to executable SCXML."""
    quiet_library_chatter()
    LIBRARIES["folders"] = [*library, *[p for p in os.environ.get("PNP_LIBRARY", "").split(":") if p.strip()]]
    LIBRARIES["builtin"] = not no_builtin


def fail(message: str, code: int = 2) -> NoReturn:
    """Print one line to stderr and exit (2: bad input)."""
    typer.echo(message, err=True)
    raise typer.Exit(code)


BUG = 4
"""Exit code of a command that failed on a bug of its own: 1 is a finding, 2 bad input, 3 no answer within a
budget (`pnp verify` inconclusive), so a bug takes the next."""

log = logging.getLogger("plugnproduce.cli")


def bug_log() -> Path:
    """The file where the command line writes the traceback of a bug."""
    return Path.home() / ".local" / "state" / "plugnproduce" / "bugs.log"


def report_bug(exc: Exception, command: str) -> NoReturn:
    """Log ``exc`` of ``command`` with its traceback to :func:`bug_log`, say in one line that it is a bug, and
    exit :data:`BUG`."""
    path = bug_log()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(path, encoding="utf-8")
    except OSError as err:
        fail(bug_message(exc, f"no file ({path} could not be written: {err.strerror or err})"), BUG)
    handler.setFormatter(logging.Formatter("%(asctime)s %(name)s %(levelname)s %(message)s"))
    log.addHandler(handler)
    try:
        log.error("bug in the command %s (pnp %s)", command, " ".join(sys.argv[1:]), exc_info=exc)
    finally:
        log.removeHandler(handler)
        handler.close()
    fail(bug_message(exc, str(path)), BUG)


def boundary(func: F) -> F:
    """Turn the project's errors into one line and exit code 2, never a traceback; anything else is a bug:
    one line saying so, the traceback in :func:`bug_log`, exit code :data:`BUG`."""

    @wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except DescriptionError as exc:
            fail(exc.location_message())
        except PlugNProduceError as exc:  # an UnknownName too: "error: unknown device 'x'; did you mean y?"
            fail(f"error: {exc}")
        except OSError as exc:
            fail(f"{getattr(exc, 'filename', None) or 'error'}: {exc.strerror or exc}")
        except (typer.Exit, typer.Abort, typer.TyperException):
            raise  # the command's own exit code or usage error
        except Exception as exc:  # noqa: BLE001 - the boundary: whatever is left is a bug
            report_bug(exc, func.__name__)

    wrapper.under_boundary = True  # type: ignore[attr-defined]  # kept by typer's own wrapper (functools.wraps)
    return wrapper  # type: ignore[return-value]


def emit_json(data: object) -> None:
    """Write a JSON document to stdout, in one write (``json.dump`` writes each of its pieces: the repairs of a
    10,000-step task are some 400,000 writes through the quiet pipe)."""
    sys.stdout.write(json.dumps(data, indent=2, sort_keys=False, default=str) + "\n")


def _command_named(args: list[str]) -> str | None:
    """The command ``args`` run, when only the application's library options come before it (not ``--help`` or
    ``--version``, which answer for the whole command line)."""
    words = iter(args)
    for word in words:
        if word == "--library":
            next(words, None)
        elif not (word == "--no-builtin" or word.startswith("--library=")):
            return None if word.startswith("-") else word
    return None


def _app_for(args: list[str]) -> typer.Typer:
    """The application with only the command ``args`` run, so that typer builds that command's parameters alone
    (building all thirty costs a tenth of a warm answer); the whole application for anything else (its help, a
    misspelt command)."""
    import copy

    from typer.main import get_command_name

    name = _command_named(args)
    commands = [c for c in app.registered_commands
                if c.callback is not None and (c.name or get_command_name(c.callback.__name__)) == name]
    groups = [g for g in app.registered_groups if g.name == name]
    if not commands and not groups:
        return app
    one = copy.copy(app)
    one.registered_commands, one.registered_groups = commands, groups
    return one


COMMAND_MODULES = ("draw", "validate", "generate", "reasoning", "devices", "run", "serve", "runs", "verify",
                   "knowledge", "plan", "resume", "teach")
"""The modules of :mod:`plugnproduce.cli` that register the commands, in the order the help lists them."""
COMMANDS = {"draw": "draw", "validate": "validate", "generate": "generate", "capabilities": "reasoning",
            "check": "reasoning", "repair": "reasoning", "explain": "reasoning", "batch": "reasoning",
            "discover": "devices", "sim": "devices", "run": "run", "report": "run", "serve": "serve", "runs": "runs",
            "verify": "verify", "vocab": "knowledge", "impact": "knowledge", "ontology": "knowledge", "plan": "plan",
            "resume": "resume", "teach": "teach"}
"""The module that registers each command (or group of commands)."""


def commands(name: str | None = None) -> typer.Typer:
    """The application with the command ``name`` registered (its module imported), or every command when ``name``
    is None or no command's."""
    module = COMMANDS.get(name or "")
    for m in (module,) if module else COMMAND_MODULES:
        importlib.import_module(f"plugnproduce.cli.{m}")
    return app


def main() -> None:
    """Entry point of the ``pnp`` console script: imports the module of the command it runs, not every command's
    (a tenth of a warm answer's time)."""
    from plugnproduce.cli.console.pipes import tolerate_closed_stdout

    tolerate_closed_stdout()
    commands(_command_named(sys.argv[1:]))
    _app_for(sys.argv[1:])()
