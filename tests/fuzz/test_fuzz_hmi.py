"""HMI requests (task validate/export/import, processes, charts, runs) mutated from the page's own.

Every answer is below 500, and an error's detail is one line quoting at most a short excerpt.
"""

from __future__ import annotations

import random
from collections.abc import Iterator

import pytest
from fuzzing import InProcessHmi, hmi_requests, mutate_request, run_hmi
from hypothesis import given, settings
from hypothesis import strategies as st

FUZZ = settings.get_profile("fuzz")


@pytest.fixture(scope="module")
def hmi(tmp_path_factory: pytest.TempPathFactory) -> Iterator[InProcessHmi]:
    app = InProcessHmi(tmp_path_factory.mktemp("runs"))
    try:
        yield app
    finally:
        app.close()


@pytest.mark.parametrize("request_", hmi_requests(), ids=lambda r: f"{r[0]} {r[1]}")
def test_the_seed_requests_are_answered(hmi: InProcessHmi, request_: tuple[str, str, dict[str, object]]) -> None:
    expected = "refused" if request_[1] in ("/api/runs", "/api/runs/unknown") else "accepted"
    assert run_hmi(hmi, request_) == expected


@settings(FUZZ, max_examples=60)
@given(seed=st.sampled_from(hmi_requests()), rng=st.randoms(use_true_random=False))
def test_mutated_requests_get_a_4xx_at_worst(hmi: InProcessHmi, seed: tuple[str, str, dict[str, object]],
                                              rng: random.Random) -> None:
    assert run_hmi(hmi, mutate_request(seed, rng)) in ("accepted", "refused")


