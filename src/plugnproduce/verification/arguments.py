"""The arguments of a request against what the device's transition takes (``pnp:accepts``).

The one place a request's arguments are judged during verification: every quantity the
transition accepts must come with the request, as a value a device can take (a finite
number where a number is given). Device limits and units, once descriptions declare them,
are checked here too.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.ontology.vocabulary import local_name


def argument_problems(device: DeviceDescription, transition: ChartTransition, arguments: Any) -> list[str]:
    """What is wrong with ``arguments`` for ``transition`` of ``device``'s chart: one phrase each (none: fine)."""
    given: Mapping[str, Any] = arguments if isinstance(arguments, Mapping) else {}
    problems = []
    for quantity in transition.accepts:
        name = local_name(quantity)
        if name not in given:
            problems.append(f"lacks the argument {name} that its transition accepts")
        elif not _finite(given[name]):
            problems.append(f"argument {name} is {given[name]!r}, not a finite value")
    return problems


def _finite(value: Any) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list | tuple):
        return all(_finite(v) for v in value)
    return True
