"""The obligation framework: verdict order, unknown never proved, vacuity, expectations."""

from __future__ import annotations

import hashlib
import time

import pytest
import z3

from cfmpa.proofs import (
    VC,
    CheckOutcome,
    CheckQuery,
    Method,
    Obligation,
    Verdict,
    Z3Query,
    discharge,
)


def _ob(build, expected=Verdict.PROVED, method=Method.Z3, timeout_ms=5_000) -> Obligation:
    return Obligation("T.x", "test", "none", "a test obligation", method, expected, build,
                      timeout_ms=timeout_ms)


def test_verdicts_are_ordered_best_first():
    order = [Verdict.FAILED, Verdict.PROVED, Verdict.UNKNOWN, Verdict.REFUTED_AS_EXPECTED]
    assert sorted(order) == [Verdict.PROVED, Verdict.REFUTED_AS_EXPECTED, Verdict.UNKNOWN,
                             Verdict.FAILED]
    assert Verdict.PROVED < Verdict.UNKNOWN < Verdict.FAILED
    assert max(Verdict.PROVED, Verdict.UNKNOWN) is Verdict.UNKNOWN


def test_a_valid_query_is_proved_with_statistics_and_hash():
    x = z3.Real("x")
    pr = discharge(_ob(lambda: Z3Query((VC("v", (("x > 1", x > 1),), x * x > 1,
                                            key_premise="x > 1"),))))
    assert pr.verdict is Verdict.PROVED and pr.as_expected
    assert pr.vcs[0].vacuity == "sat" and pr.vcs[0].answer == "unsat"
    assert pr.statistics and "memory" not in pr.statistics
    assert pr.sha256 == hashlib.sha256(pr.smtlib.encode()).hexdigest()
    assert "(check-sat)" in pr.smtlib and "(assert (> x 1.0))" in pr.smtlib


def test_unknown_is_never_proved():
    # x^3 + y^3 = z^3 over positive integers: Z3 cannot refute it and searches until the timeout.
    x, y, z = z3.Ints("x y z")
    hyps = (("positive", z3.And(x >= 1, y >= 1, z >= 1)),)
    goal = x * x * x + y * y * y != z * z * z
    t0 = time.perf_counter()
    pr = discharge(_ob(lambda: Z3Query((VC("fermat3", hyps, goal),)), timeout_ms=300))
    assert time.perf_counter() - t0 < 20           # the timeout was applied
    assert pr.verdict is Verdict.UNKNOWN and not pr.as_expected
    assert pr.vcs[0].answer == "unknown" and pr.reason_unknown


def test_vacuous_hypotheses_fail():
    x = z3.Int("x")
    hyps = (("x > 0", x > 0), ("x < 0", x < 0))
    pr = discharge(_ob(lambda: Z3Query((VC("v", hyps, x == 7),))))
    assert pr.verdict is Verdict.FAILED and pr.reason.startswith("vacuous")
    assert pr.vcs[0].vacuity == "unsat" and pr.vcs[0].answer == "unsat"


def test_a_witness_only_helps_the_vacuity_check():
    x = z3.Int("x")
    vc = VC("v", (("x > 0", x > 0),), x > -1, witness=((x, z3.IntVal(-5)),))
    pr = discharge(_ob(lambda: Z3Query((vc,))))
    # The witness contradicts the hypotheses: no model extends it, so the check fails.
    assert pr.verdict is Verdict.FAILED and "vacuous" in pr.reason


def test_refutation_gives_a_counterexample_and_fails_when_unexpected():
    x = z3.Int("x")
    q = lambda: Z3Query((VC("v", (("x > 0", x > 0),), x > 5),))  # noqa: E731
    bad = discharge(_ob(q))
    assert bad.verdict is Verdict.FAILED and bad.counterexample and "x = " in bad.counterexample
    good = discharge(_ob(q, expected=Verdict.REFUTED_AS_EXPECTED))
    assert good.verdict is Verdict.REFUTED_AS_EXPECTED and good.as_expected


def test_a_proof_expected_to_be_refuted_is_not_as_expected():
    x = z3.Int("x")
    pr = discharge(_ob(lambda: Z3Query((VC("v", (("x > 5", x > 5),), x > 0),)),
                       expected=Verdict.REFUTED_AS_EXPECTED))
    assert pr.verdict is Verdict.PROVED and not pr.as_expected


def test_exceptions_and_undecided_checks():
    def boom():
        raise RuntimeError("no query")
    pr = discharge(_ob(boom))
    assert pr.verdict is Verdict.FAILED and "RuntimeError" in pr.reason
    undecided = discharge(_ob(lambda: CheckQuery(lambda: CheckOutcome(None, "cannot tell"), "c"),
                              method=Method.SYMPY))
    assert undecided.verdict is Verdict.UNKNOWN
    false = discharge(_ob(lambda: CheckQuery(lambda: CheckOutcome(False, "no", "cex"), "c"),
                          method=Method.DATA))
    assert false.verdict is Verdict.FAILED and false.counterexample == "cex"


def test_vc_without_removes_one_premise():
    x = z3.Int("x")
    vc = VC("v", (("a", x > 0), ("b", x < 9)), x > -1, key_premise="a")
    assert [n for n, _ in vc.without("a").hypotheses] == ["b"]
    with pytest.raises(KeyError):
        vc.without("c")


def test_a_check_hashes_its_outcome_and_source():
    # Same inputs, another computed result: another hash (a data change is not "same").
    same = lambda holds, detail: _ob(  # noqa: E731
        lambda: CheckQuery(lambda: CheckOutcome(holds, detail), "inputs"), method=Method.DATA)
    a, b = discharge(same(True, "N = 70")), discharge(same(True, "N = 71"))
    assert a.verdict is b.verdict is Verdict.PROVED and a.sha256 != b.sha256
    assert "N = 71" in b.smtlib and a.sha256 == discharge(same(True, "N = 70")).sha256
    from cfmpa.proofs._obl_margin import _cos_bound
    assert "def _cos_bound" in _cos_bound().content


def test_a_check_that_runs_too_long_is_unknown():
    def slow() -> CheckOutcome:
        time.sleep(5)
        return CheckOutcome(True, "late")
    pr = discharge(_ob(lambda: CheckQuery(slow, "slow"), method=Method.SYMPY, timeout_ms=200))
    assert pr.verdict is Verdict.UNKNOWN and "timed out" in pr.reason


def test_refuted_obligations_label_their_second_check_as_a_refutation():
    x = z3.Real("x")
    q = lambda: Z3Query((VC("v", (("x > 1", x > 1),), x > 2),))  # noqa: E731
    refuted = discharge(_ob(q, expected=Verdict.REFUTED_AS_EXPECTED))
    assert refuted.verdict is Verdict.REFUTED_AS_EXPECTED
    assert "refutation (expect sat" in refuted.smtlib and "expect unsat" not in refuted.smtlib
    assert "proof (expect unsat)" in discharge(_ob(q)).smtlib


def test_a_repeated_vc_name_is_keyed_by_its_position():
    # The lock's and results.json's key of each VC (the prove run and bench/tune_cvc5.py both
    # read them from vc_keys).
    import z3 as _z3

    from cfmpa.proofs._obligation import vc_keys
    x = _z3.Int("x")
    vcs = [VC(n, (), x == x) for n in ("a", "b", "a", "a")]
    assert vc_keys(vcs) == ["a", "b", "a#3", "a#4"]
