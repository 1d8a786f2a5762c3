"""`cfmpa selftest --code`: source mutations of a copy, run in processes that import the copy."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from cfmpa.cli import main
from cfmpa.errors import InputError
from cfmpa.runs._code_mutants import (
    CODE_MUTANTS,
    CodeMutant,
    _check_prove,
    _env,
    code_mutation_rows,
    imports_copy,
    mutated_copy,
)

REPO = Path(__file__).resolve().parents[2]
#: The smallest bundled workcell's translation checks: seconds, where the whole prove is a minute.
QUICK = ["Scenario.narrow-gap.translation_original"]


@pytest.mark.parametrize("m", CODE_MUTANTS, ids=[m.name for m in CODE_MUTANTS])
def test_each_mutant_is_one_real_edit_of_todays_source(m: CodeMutant, tmp_path: Path):
    copy = mutated_copy(m, tmp_path)
    original = (REPO / m.file).read_text()
    mutated = (copy / "cfmpa" / m.file).read_text()
    assert mutated != original
    for old, new in m.edits:
        assert original.count(old) == 1 and new in mutated
    compile(mutated, m.file, "exec")          # still Python: the checks must judge it


@pytest.mark.parametrize("where", ["work", "checkout"])
def test_the_copy_is_what_the_processes_import(tmp_path: Path, where: str):
    # Even started in the checkout, whose cfmpa/ folder a plain `python -c` would import first
    # (the first version of the tests check ran there and judged the original).
    copy = mutated_copy(CODE_MUTANTS[0], tmp_path / "copy")
    cwd = REPO if where == "checkout" else tmp_path
    assert imports_copy(copy, cwd)
    p = subprocess.run([sys.executable, "-P", "-c", "import cfmpa.impl._fast_builtdr as f; "
                        "print(f.__file__); print('# mutant' in open(f.__file__).read())"],
                       env=_env(copy), cwd=cwd, capture_output=True, text=True, check=True)
    file, mutated = p.stdout.split()
    assert Path(file).is_relative_to(copy) and mutated == "True"


def test_an_edit_that_does_not_match_once_is_refused(tmp_path: Path):
    ghost = CodeMutant("ghost", "no such text", "impl/_regions.py", (("no such text", "x"),))
    with pytest.raises(InputError, match="matches 0 times"):
        mutated_copy(ghost, tmp_path)


@pytest.mark.slow     # two prove runs in fresh copies, each compiling the kernels: about a minute
def test_prove_passes_on_the_unmutated_copy_and_catches_the_free_rest_layer(tmp_path: Path):
    # The same check on the copy with no edit passes: what it catches is the mutant's doing.
    clean = mutated_copy(None, tmp_path / "clean")
    (tmp_path / "w1").mkdir()
    assert _check_prove(clean, tmp_path / "w1", QUICK) == (False, "every verdict as expected")
    rows = code_mutation_rows(["rest_layer_free"], checks=("prove",), prove_only=QUICK)
    assert rows[0].caught == {"prove": True}
    assert "Scenario.narrow-gap.translation_original" in rows[0].detail["prove"]


def test_bad_options_exit_2_naming_the_field(capsys: pytest.CaptureFixture[str]):
    assert main(["selftest", "--code", "--mutant", "nope"]) == 2
    assert "--mutant is not one of rest_layer_free" in capsys.readouterr().err
    assert main(["selftest", "--code", "--checks", "prove,bogus"]) == 2
    assert "--checks is not one of prove, contracts, tests, got 'bogus'" in capsys.readouterr().err
    assert main(["selftest", "--json", "x.json"]) == 2
    assert "--json is an option of cfmpa mutants" in capsys.readouterr().err
    # cfmpa mutants is the new spelling of selftest --code: the same checks of its options.
    assert main(["mutants", "--mutant", "nope"]) == 2
    assert "--mutant is not one of rest_layer_free" in capsys.readouterr().err


@pytest.mark.slow
def test_cfmpa_prove_catches_every_mutant(tmp_path: Path):
    out = tmp_path / "mutants.json"
    assert main(["selftest", "--code", "--checks", "prove", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert [r["mutant"] for r in doc["mutants"]] == [m.name for m in CODE_MUTANTS]
    assert all(r["caught"]["prove"] for r in doc["mutants"])


#: Each fault in what the safety theorem reads, and the obligation that must fail on it under
#: --repin (its statement re-pinned, so only a refuted or undecided VC can catch it).
SAFETY_FAULTS = {"modified_box_half_step": "Safety.modified.principal_in_layer_box",
                 "lattice_snap_widened": "Safety.region_soundness",
                 "eps_zero": "Safety.separation",
                 "composition_region_strengthened": "Safety.modified.composition",
                 "witness_edge_loosened": "Witness.labels_sound"}


@pytest.mark.slow     # one prove run per fault in a fresh copy: about a minute in all
@pytest.mark.parametrize("name", list(SAFETY_FAULTS))
def test_a_safety_fault_fails_its_obligation_under_repin(name: str):
    rows = code_mutation_rows([name], checks=("prove",), prove_only=[SAFETY_FAULTS[name]])
    assert rows[0].caught == {"prove": True}, rows[0].detail
    assert SAFETY_FAULTS[name] in rows[0].detail["prove"]
