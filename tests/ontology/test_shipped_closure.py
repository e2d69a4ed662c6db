"""The built-in ontology's closure ships with the package: a fresh or read-only home pays no HermiT."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce.ontology import taxonomy as taxonomy_module
from plugnproduce.ontology.taxonomy import SHIPPED_CLOSURE, _digest, load_taxonomy, ontology_files, shipped_closure
from plugnproduce.resources import ontology_path


def test_the_shipped_closure_is_that_of_the_ontology_as_it_is() -> None:
    # Fails after an edit of ontology/pnp.ttl: refresh with `python -m plugnproduce.ontology.taxonomy`.
    assert shipped_closure(_digest(ontology_files())) is not None


def test_a_fresh_home_loads_the_builtin_closure_without_the_reasoner(tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    def no_hermit(*args: object, **kwargs: object) -> None:
        raise AssertionError("HermiT was called")

    monkeypatch.setattr(taxonomy_module, "classify", no_hermit)
    taxonomy = load_taxonomy(cache_dir=tmp_path / "empty-cache")
    assert taxonomy.implied_skills["http://plugnproduce.org/ontology#ParallelGripper"]
    assert not (tmp_path / "empty-cache").exists()  # nothing written: nothing to cache


def test_a_closure_of_other_content_is_not_used(tmp_path: Path) -> None:
    assert shipped_closure("0" * 64) is None
    assert (ontology_path() / SHIPPED_CLOSURE).is_file()
