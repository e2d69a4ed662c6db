"""The ``pnp`` command line: a thin layer over :mod:`plugnproduce.service`.

Exit codes: 0 done/ok; 1 a finding (invalid, infeasible, implausible, refuted, failed run);
2 bad input or usage, reported as one ``file:line: message`` line, never a traceback;
3 no answer within a budget (``pnp verify`` inconclusive); 4 a bug of pnp itself (one line saying so,
the traceback in ``~/.local/state/plugnproduce/bugs.log``).
Each command module registers its commands on :data:`app`.
"""

from __future__ import annotations

from plugnproduce.cli.app import app, main

# Command modules register themselves on import.
from plugnproduce.cli import draw, validate  # noqa: E402,F401  isort: skip
from plugnproduce.cli import generate, reasoning  # noqa: E402,F401  isort: skip
from plugnproduce.cli import devices, run, serve  # noqa: E402,F401  isort: skip
from plugnproduce.cli import runs, verify  # noqa: E402,F401  isort: skip
from plugnproduce.cli import knowledge, plan, resume, teach  # noqa: E402,F401  isort: skip

__all__ = ["app", "main"]
