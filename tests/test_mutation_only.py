"""scripts/mutation.py --only: mutate and count only the mutants of the functions named (mutmut's keys, * allowed)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parents[1] / "scripts"))
import mutation  # noqa: E402

FILE = "src/plugnproduce/batch/feasibility.py"


def test_only_narrows_the_functions_mutmut_runs_and_the_mutants_counted(tmp_path: Path,
                                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    given: list[mutation.Guard] = []
    monkeypatch.setattr(mutation, "run_guard", lambda guard, *_a, **_k: given.append(guard) or {"mutants": 0})
    assert mutation.main(["--only", "xǁFeasibilityǁ__init__", "--only", "x__key_*", "reasoning-feasibility"]) == 0
    (guard,) = given
    assert guard.functions == ("xǁFeasibilityǁ__init__", "x__key_*")
    assert guard.files == (FILE,)  # the module's files and tests are kept
    meta = tmp_path / "mutants" / (FILE + ".meta")
    meta.parent.mkdir(parents=True)
    keys = {"plugnproduce.batch.feasibility.xǁFeasibilityǁ__init____mutmut_1": 1,
            "plugnproduce.batch.feasibility.x__key_masks__mutmut_13": 0,
            "plugnproduce.batch.feasibility.x__findings__mutmut_2": None,
            "plugnproduce.batch.feasibility.xǁFeasibilityǁfindings__mutmut_3": 0}
    meta.write_text(json.dumps({"exit_code_by_key": keys}), encoding="utf-8")
    assert mutation._results(guard, tmp_path) == {"plugnproduce.batch.feasibility.xǁFeasibilityǁ__init____mutmut_1": 1,
                                                  "plugnproduce.batch.feasibility.x__key_masks__mutmut_13": 0}


def test_only_refuses_an_encoding_and_a_run_of_every_module_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert mutation.main(["--only", "x_literal", "rules-chain"]) == 2
    assert mutation.main(["--only", "x_literal"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == ["scripts/mutation.py: --only names functions of Python modules: name those modules, no encoding"] * 2
