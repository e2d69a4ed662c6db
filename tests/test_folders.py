"""The folders the controller writes to come from platformdirs: the cache folder (units, engines, taxonomy closures, the simulated
cell's control file, the kept help) and the runs folder, with ``PNP_RUNS`` still naming another runs folder."""

from __future__ import annotations

from pathlib import Path

import platformdirs
import pytest

from plugnproduce import folders, helpcache, service
from plugnproduce.batch import enginecache
from plugnproduce.description.quantities import unitcache
from plugnproduce.knowledge.libraries import Library, tbox_files
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.sim import control


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A user's home of its own, with no XDG folders named."""
    monkeypatch.setenv("HOME", str(tmp_path))
    for name in ("XDG_CACHE_HOME", "XDG_STATE_HOME", "PNP_RUNS"):
        monkeypatch.delenv(name, raising=False)
    return tmp_path


def test_every_cache_is_in_the_platforms_cache_folder(home: Path) -> None:
    expected = Path(platformdirs.user_cache_dir("plugnproduce"))
    assert expected.is_relative_to(home)
    assert folders.cache_folder() == expected
    assert unitcache.cache_folder() == expected
    assert enginecache.cache_folder() == expected
    assert control.default_state_file().parent == expected
    assert Path(helpcache.help_file()).parent == expected


def test_xdg_cache_home_moves_every_cache_and_the_kept_help_alike(home: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    elsewhere = home / "elsewhere"
    monkeypatch.setenv("XDG_CACHE_HOME", str(elsewhere))
    assert folders.cache_folder() == Path(platformdirs.user_cache_dir("plugnproduce"))
    assert folders.cache_folder().is_relative_to(elsewhere)
    assert Path(helpcache.help_file()).parent == folders.cache_folder()
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/cache")  # not absolute: platformdirs ignores it, and so does the help
    assert Path(helpcache.help_file()).parent == folders.cache_folder() == home / ".cache" / "plugnproduce"


def test_runs_go_to_the_platforms_state_folder_unless_pnp_runs_names_one(home: Path,
                                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    assert service.runs_folder() == Path(platformdirs.user_state_dir("plugnproduce")) / "runs"
    assert service.runs_folder().is_relative_to(home)
    monkeypatch.setenv("XDG_STATE_HOME", str(home / "state"))
    assert service.runs_folder() == home / "state" / "plugnproduce" / "runs"
    monkeypatch.setenv("PNP_RUNS", str(home / "my-runs"))
    assert service.runs_folder() == home / "my-runs"


def test_xdg_cache_home_moves_the_closure_of_a_librarys_taxonomy_too(home: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The closure HermiT computes for a user's library is kept where every other cache is, not in ~/.cache."""
    elsewhere = home / "elsewhere"
    monkeypatch.setenv("XDG_CACHE_HOME", str(elsewhere))
    library = Path(__file__).parent / "data" / "libraries" / "transport-lock"
    taxonomy = load_taxonomy(tbox_files([Library(library)]))
    assert "http://example.org/transport-lock#TransportLocked" in taxonomy.superclasses
    assert [p.name for p in (elsewhere / "plugnproduce").glob("taxonomy-*.json")] == [
        f"taxonomy-{taxonomy.digest[:32]}.json"]
    assert not (home / ".cache").exists()
