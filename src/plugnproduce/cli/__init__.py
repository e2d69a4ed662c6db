"""The ``pnp`` command line: a thin layer over :mod:`plugnproduce.service`.

Exit codes: 0 done/ok; 1 a finding (invalid, infeasible, implausible, refuted, failed run);
2 bad input or usage, reported as one ``file:line: message`` line, never a traceback;
3 no answer within a budget (``pnp verify`` inconclusive); 4 a bug of pnp itself (one line saying so,
the traceback in ``~/.local/state/plugnproduce/bugs.log``).
Each command module registers its commands on the application (:mod:`plugnproduce.cli.application`). The console
script (:func:`main`) imports only the module of the command it runs; :data:`app`, asked for, has every command.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.cli.application import commands, main

if TYPE_CHECKING:
    from plugnproduce.cli.application import app


def __getattr__(name: str) -> object:  # PEP 562: the whole application, its command modules imported on first use
    if name == "app":
        return commands()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["app", "main"]
