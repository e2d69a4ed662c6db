"""``python -m plugnproduce`` and the ``pnp`` command: the command line, and ``--help`` from where it was kept."""

import gc
import sys

from plugnproduce.helpcache import keeping, print_kept


def run() -> None:
    """Entry point of the ``pnp`` console script.

    Once the command line is imported, what it made (typer's and click's modules, the commands) is kept out of the
    cyclic garbage collector's walks (:func:`gc.freeze`): it lives as long as the process, and each full collection
    while a command starts would walk it again (a twentieth of a warm ``pnp capabilities``). Reference counting
    still frees it, and what the command makes from then on is collected as usual."""
    if print_kept(sys.argv[1:]):
        return
    from plugnproduce.cli import main

    gc.freeze()
    keeping(sys.argv[1:], main)


if __name__ == "__main__":
    run()
