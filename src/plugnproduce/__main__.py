"""``python -m plugnproduce`` and the ``pnp`` command: the command line, and ``--help`` from where it was kept."""

import sys

from plugnproduce.helpcache import keeping, print_kept


def run() -> None:
    """Entry point of the ``pnp`` console script."""
    if print_kept(sys.argv[1:]):
        return
    from plugnproduce.cli import main

    keeping(sys.argv[1:], main)


if __name__ == "__main__":
    run()
