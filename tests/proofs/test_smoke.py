"""Smoke tests inside the while-programs: every Assume, branch and loop must be reachable."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
import z3

from cfmpa.proofs import (
    Method,
    Obligation,
    Verdict,
    Z3Query,
    collect_obligations,
    discharge,
    run_prove,
)
from cfmpa.proofs._obligation import _smoke
from cfmpa.proofs._while import Assign, Assume, For, If, Seq, smoke_tests, verification_conditions

REPO = Path(__file__).resolve().parents[2]


def _answers(tests) -> dict[str, str]:
    return {t.name.split(": ", 1)[1]: _smoke(t, {}).answer for t in tests}


def test_every_point_of_a_small_program_is_tested():
    x, y, i, n = z3.Ints("x y i n")
    prog = Seq((If(x > 0, Assign(y, z3.IntVal(1)), Assume(x > 5)),
                For("L", i, z3.IntVal(0), n, y >= 0,
                    Seq((If(i > n, Assign(y, y + 1)), Assign(y, y + 1))))))
    got = _answers(smoke_tests("t", x >= 0, prog))
    assert got == {
        "if x > 0: then": "sat", "if x > 0: else": "sat",
        "if x > 0: else: assume x > 5": "unsat",          # x <= 0 there
        "loop L: entry (invariant)": "sat", "loop L: body (guard true)": "sat",
        "loop L: exit (guard false)": "sat",
        "if i > n: then": "unsat",                         # i < n inside the loop
        "if i > n: else": "sat"}


def test_an_assume_that_rules_out_a_case_of_its_own_condition_is_vacuous():
    found, ok = z3.Bools("found ok")
    contract = z3.And(z3.Implies(found, ok), z3.Implies(z3.Not(found), z3.Not(ok)))
    good = _answers(smoke_tests("t", z3.BoolVal(True), Assume(contract)))
    assert set(good.values()) == {"sat"} and len(good) == 3     # the assume and 2 cases
    bad = _answers(smoke_tests("t", z3.BoolVal(True), Assume(z3.And(contract, found))))
    assert bad["assume ..., case Not(found)"] == "unsat"


def test_a_vacuous_program_point_fails_its_obligation():
    x = z3.Int("x")
    prog = If(x > 0, Assume(x < 0), Assign(x, x + 1))
    vcs = verification_conditions("p", x >= 0, prog, x >= 0)
    ob = Obligation("T.smoke", "t", "r", "s", Method.Z3, Verdict.PROVED,
                    lambda: Z3Query(vcs, smoke=smoke_tests("p", x >= 0, prog)))
    pr = discharge(ob)
    # Every VC is valid (the dead branch proves anything), and the smoke test says why.
    assert all(v.answer == "unsat" for v in pr.vcs)
    assert pr.verdict is Verdict.FAILED and "vacuous program" in pr.reason
    assert "assume x < 0" in pr.reason


@pytest.mark.parametrize("ident", ["Thm1.builtdr", "Thm2.searchoptpath",
                                   "Thm4.searchoptpath_tight", "Prop8.prestrength_thm4"])
def test_the_programs_are_not_vacuous(ident: str):
    ob = next(o for o in collect_obligations("/nonexistent", [ident]))
    q = ob.build()
    assert q.smoke
    results = [_smoke(t, {}) for t in q.smoke]
    assert [(r.name, r.answer) for r in results if r.answer != "sat"] == []


def _assume_found(monkeypatch) -> None:
    """The seeded fault: the search wrapper assumes its contract and found (the search
    always finds a path)."""
    import cfmpa.proofs._obl_paths as paths
    real = paths.Assume
    monkeypatch.setattr(paths, "Assume", lambda c: real(z3.And(c, z3.Bool("found"))))


# Slow: the default run keeps the same mutant through cfmpa prove (and test_mutants.py's).
@pytest.mark.slow
def test_assuming_found_in_the_search_wrapper_fails_theorems_2_and_4(monkeypatch, tmp_path):
    _assume_found(monkeypatch)
    only = ["Thm2.searchoptpath", "Thm4.searchoptpath", "Thm4.searchoptpath_tight",
            "Prop8.prestrength_thm4"]
    for ob in collect_obligations("/nonexistent", only):
        pr = discharge(ob)
        assert all(v.answer == "unsat" for v in pr.vcs), ob.id   # the VCs alone still pass
        assert pr.verdict is Verdict.FAILED and "case Not(found)" in pr.reason, ob.id
    out = io.StringIO()
    rc = run_prove(out_dir=tmp_path, only=only, stream=out)
    assert rc == 1
    doc = json.loads((tmp_path / "results.json").read_text())
    assert {o["id"]: o["verdict"] for o in doc["obligations"]} == dict.fromkeys(only, "failed")


def test_cfmpa_prove_exits_1_when_the_search_always_finds_a_path(monkeypatch, tmp_path):
    from cfmpa.cli import main
    _assume_found(monkeypatch)
    rc = main(["prove", "--out", str(tmp_path), "--only", "Thm2", "--only", "Thm4"])
    assert rc == 1
    doc = json.loads((tmp_path / "results.json").read_text())
    assert all(o["verdict"] == "failed" and "vacuous program" in o["reason"]
               for o in doc["obligations"])
