"""The arguments of a request against what the device's transition takes (``pnp:accepts``).

The one place a request's arguments are judged during verification, by the device's own terms
(its ``pnp:RequestArgument`` contracts): every argument the device needs (required, with no
default of its own) must come with the request, and each value sent must be one a device can
take: finite, of the argument's own datatype and a number within the device's limits (the
generated program sends values in the device's unit), as the executor judges each request
before it goes out. The plausibility check holds the task to the same limits before a program
is generated; this is the proof that the program really sends what it promised.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.description.quantities.contracts import breach
from plugnproduce.ontology.iris import local_name


def argument_problems(device: DeviceDescription, transition: ChartTransition, arguments: Any) -> list[str]:
    """What is wrong with ``arguments`` for ``transition`` of ``device``'s chart: one phrase each (none: fine)."""
    given: Mapping[str, Any] = arguments if isinstance(arguments, Mapping) else {}
    problems = []
    request = transition.request.name if transition.request else ""
    for quantity in transition.accepts:
        name, contract = local_name(quantity), device.argument(request, quantity)
        value = given.get(name)
        if name not in given:
            if contract.needed:
                problems.append(f"lacks the argument {name} that its transition accepts")
        elif not _finite(value):
            problems.append(f"argument {name} is {value!r}, not a finite value")
        elif (why := breach(value, contract.unit, contract)) is not None:
            problems.append(f"argument {name} is {value!r}, beyond the device's contract: it {why}")
    return problems


def _finite(value: Any) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list | tuple):
        return all(_finite(v) for v in value)
    return True
