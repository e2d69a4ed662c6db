"""Fixtures of the fuzz tests: a private copy of the built-in descriptions, and Hypothesis settings.

The cases are bounded (few examples, no deadline: the shared machines are slow at times);
``scripts/fuzz.py`` runs the same targets for as many cases as one wants.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from fuzzing import Workspace
from hypothesis import HealthCheck, settings

settings.register_profile(
    "fuzz", max_examples=40, deadline=None, derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)


@pytest.fixture(scope="module")
def workspace() -> Iterator[Workspace]:
    """The built-in descriptions copied to a temporary folder, where each case is written beside them."""
    ws = Workspace()
    try:
        yield ws
    finally:
        ws.close()
