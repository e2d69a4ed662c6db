"""``python -m plugnproduce``: the same as the ``pnp`` command."""

from plugnproduce.cli import main

main()
