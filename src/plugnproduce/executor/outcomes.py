"""The outcome a device reports, however it writes it: full IRI, prefixed name or local name.

The formats let a device name an outcome concept in any of these forms
(``http://plugnproduce.org/ontology#PartFound``, ``pnp:PartFound``, ``PartFound``); all are the same
outcome, resolved through the loaded knowledge's prefixes. The task chart's loops and branches compare
outcomes by their local names, so the executor hands the chart the resolved outcome's local name. An
outcome the step's process does not declare is a fault, never a silent "no branch".
"""

from __future__ import annotations

from collections.abc import Mapping

from plugnproduce.description.quantities.contracts import shorten
from plugnproduce.ontology.iris import PNP_IRI, local_name

MAX_NAME = 2048
"""The longest outcome name read."""

DEFAULT_PREFIXES = {"pnp": PNP_IRI}
PARAM = "outcome"
"""The event value that carries a process's outcome."""


def resolve(reported: object, declared: tuple[str, ...], prefixes: Mapping[str, str]) -> str | None:
    """The declared outcome (IRI) ``reported`` names, or None if it names none of them."""
    if not isinstance(reported, str) or not reported or len(reported) > MAX_NAME:
        return None
    if reported in declared:
        return reported
    prefix, colon, local = reported.partition(":")
    if colon:
        namespace = prefixes.get(prefix)
        return namespace + local if namespace is not None and namespace + local in declared else None
    named = [o for o in declared if local_name(o) == reported]
    pnp = [o for o in named if o.startswith(PNP_IRI)]  # a local name is the pnp term's, as in every description
    return (pnp or named)[0] if len(pnp) == 1 or len(named) == 1 else None


def undeclared(device: str, reported: object, process: str, declared: tuple[str, ...]) -> str:
    """The fault's words for an outcome the process does not declare."""
    names = ", ".join(local_name(o) for o in declared)
    return (f"{device} reported outcome {shorten(reported)}, which {process} does not declare "
            f"(it declares {names}); the task cannot tell which way to go")
