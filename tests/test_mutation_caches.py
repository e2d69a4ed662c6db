"""Mutation runs: each pytest session keeps its results in a cache folder of its own (scripts/mutation.py's plugin).

All mutants of a module share one mutated source, so one digest of the package's code: a result kept in the user's
cache folder by the unmutated code (the knowledge, a device, a task file, a cycle time estimate) would answer for
every mutant, and a mutant of a function that makes it would never run. The plugin gives every session, and the
processes it starts, a cache folder of its own, removed when the session ends; it starts with only what no mutated
function makes (the seed: the taxonomy closures and the unit table).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "scripts"))
import mutation  # noqa: E402

SESSION = '''import subprocess
import sys

from plugnproduce import folders


def test_the_cache_folder_is_empty_and_the_child_processes_share_it():
    here = folders.cache_folder()
    assert sorted(p.name for p in here.iterdir()) == ["taxonomy-seeded.json"]  # what the seed gave, nothing else
    (here / "kept").write_text("made by this session")
    child = subprocess.run([sys.executable, "-c", "from plugnproduce import folders; print(folders.cache_folder())"],
                           capture_output=True, text=True, check=True)
    assert child.stdout.strip() == str(here)
    print("cache folder:", here)
'''


def session(tmp_path: Path, caches: Path, mutant: str) -> Path:
    """Run one pytest session with the plugin, as mutmut runs one mutant's tests; the cache folder it used."""
    src = Path(__file__).parents[1] / "src"
    env = {**os.environ, "PYTHONPATH": f"{tmp_path}{os.pathsep}{src}", "MUTANT_UNDER_TEST": mutant,
           "PNP_MUTATION_CACHES": str(caches), "PNP_MUTATION_SEED": str(tmp_path / "seed"),
           "XDG_CACHE_HOME": str(tmp_path / "user-cache")}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-s", "-n", "0", "-p", "no:cacheprovider", "-p",
                           mutation.PLUGIN, "-c", os.devnull, "--rootdir", str(tmp_path), str(tmp_path / "test_one.py")],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    (line,) = [x for x in done.stdout.splitlines() if "cache folder:" in x]
    return Path(line.split("cache folder:", 1)[1].strip())


@pytest.fixture
def plugin(tmp_path: Path) -> Path:
    (tmp_path / f"{mutation.PLUGIN}.py").write_text(mutation.PLUGIN_TEXT, encoding="utf-8")
    (tmp_path / "test_one.py").write_text(SESSION, encoding="utf-8")
    (tmp_path / "seed" / "plugnproduce").mkdir(parents=True)
    (tmp_path / "seed" / "plugnproduce" / "taxonomy-seeded.json").write_text("{}", encoding="utf-8")
    return tmp_path


def test_each_session_keeps_its_results_apart_from_the_users_cache_and_from_the_others(plugin: Path) -> None:
    caches = plugin / "caches"
    caches.mkdir()
    first = session(plugin, caches, "plugnproduce.codegen.specific.x_literal__mutmut_1")
    second = session(plugin, caches, "plugnproduce.codegen.specific.x_literal__mutmut_2")
    assert first != second
    assert first.is_relative_to(caches) and second.is_relative_to(caches)
    assert list(caches.iterdir()) == []  # each removed when its session ended
    assert not (plugin / "user-cache").exists()
    assert [p.name for p in (plugin / "seed" / "plugnproduce").iterdir()] == ["taxonomy-seeded.json"]


def test_a_module_whose_code_makes_a_seeded_result_starts_without_it(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    user = tmp_path / "user-cache"
    (user / "plugnproduce").mkdir(parents=True)
    for name in ("taxonomy-1.json", "units-1.json", "knowledge-1.pickle", "cycletime-1.pickle"):
        (user / "plugnproduce" / name).write_text("kept", encoding="utf-8")
    monkeypatch.setenv("XDG_CACHE_HOME", str(user))
    guards = {g.name: g for g in (*mutation.GUARDS, *mutation.CORE)}
    seeded = {}
    for name in ("codegen-specific", "safeio"):
        mutation._seed(guards[name], tmp_path / name)
        seeded[name] = sorted(p.name for p in (tmp_path / name / "seed" / "plugnproduce").iterdir())
    assert seeded == {"codegen-specific": ["taxonomy-1.json", "units-1.json"], "safeio": ["units-1.json"]}
