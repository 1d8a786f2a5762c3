"""The standard SMT-LIB printer, the cvc5 replay and the SOS certificates."""

from __future__ import annotations

import re
from concurrent.futures import Future
from fractions import Fraction

import pytest
import z3

from cfmpa.proofs import VC, Method, Obligation, Verdict, Z3Query, collect_obligations, discharge
from cfmpa.proofs._cvc5 import Cvc5Answer, Cvc5Worker, cvc5_version
from cfmpa.proofs._obligation import discharge_pending
from cfmpa.proofs._smtlib import NotStandard, smtlib_query
from cfmpa.proofs._sos import Certificate, Square, check_certificate

Z3_OBS = [o for o in collect_obligations("/nonexistent") if o.method is Method.Z3]
needs_cvc5 = pytest.mark.skipif(cvc5_version() is None, reason="cvc5 is not installed")


def _text(vc: VC) -> str:
    return smtlib_query([h for _, h in vc.hypotheses], vc.goal).text


def _z3_answer(text: str) -> z3.CheckSatResult:
    s = z3.Solver(ctx=z3.Context())
    s.set("timeout", 20_000)
    s.from_string(text)
    return s.check()


@pytest.mark.parametrize("ident", ["Def2.is_convex", "Def3.convex_hull", "Lemma2.convex_union",
                                   "Sep.distance_monotone", "Thm1.builtdr", "Prop8.optimal_cost"])
def test_the_text_is_standard_and_means_the_same(ident: str):
    # Lambdas (Def2, Def3, Lemma2, Sep), stores into 3-index arrays (Thm1), functions (Prop8).
    ob = next(o for o in Z3_OBS if o.id == ident)
    for vc in ob.build().vcs:
        text = _text(vc)
        assert text.startswith("(set-logic ") and "lambda" not in text
        # Arrays are curried: no array sort or select with two indices left.
        assert not re.search(r"\(Array \w+ \w+ ", text)
        assert "(as const" not in text and "(_ as-array" not in text
        # Z3 reads the text back and still proves the VC: the rendering keeps its meaning.
        assert _z3_answer(text) == z3.unsat, (ident, vc.name)


def test_a_lambda_not_applied_has_no_standard_rendering():
    x = z3.Int("x")
    a = z3.Array("a", z3.IntSort(), z3.IntSort())
    with pytest.raises(NotStandard, match="lambda"):
        smtlib_query([a == z3.Lambda([x], x + 1)], a[0] == 1)
    # Applied, it is beta-reduced: (select (lambda x. x + 1) 0) is 0 + 1.
    text = smtlib_query([], z3.Lambda([x], x + 1)[0] == 1).text
    assert "lambda" not in text and "(+ 0 1)" in text


def test_equal_quantifiers_print_equally_and_outer_existentials_are_skolemised():
    x = z3.Int("x")
    f = z3.Function("f", z3.IntSort(), z3.IntSort())
    every = z3.ForAll([x], f(x) > 0)
    text = smtlib_query([every, z3.Implies(every, f(1) > 5)], z3.ForAll([x], f(x) >= 0)).text
    forall = re.findall(r"\(forall \(\(\|x!1\.0\| Int\)\) \(> \(\|f\| \|x!1\.0\|\) 0\)\)", text)
    assert len(forall) == 2                    # the same formula, twice, with the same names
    assert "x!sk" in text                      # the negated universal goal, opened


def test_the_hash_is_the_statements():
    vc = VC("v", (("a", z3.Int("x") > 1),), z3.Int("x") > 0)
    same = VC("w", (("another label", z3.Int("x") > 1),), z3.Int("x") > 0)
    other = VC("v", (("a", z3.Int("x") > 2),), z3.Int("x") > 0)
    h = lambda v: smtlib_query([f for _, f in v.hypotheses], v.goal).sha256  # noqa: E731
    assert h(vc) == h(same) != h(other)


@needs_cvc5
def test_cvc5_replays_a_proof_and_a_refutation():
    x = z3.Real("x")
    with Cvc5Worker() as w:
        assert w.check(smtlib_query([x > 1], x > 0).text).answer == "unsat"
        assert w.check(smtlib_query([x > 1], x > 2).text).answer == "sat"
        bad = w.check("(set-logic QF_LRA)(assert (> |nope| 0.0))(check-sat)")
        assert bad.answer == "unknown" and "cvc5 error" in bad.reason


@needs_cvc5
def test_to_int_of_a_real_gets_a_mixed_logic_that_cvc5_accepts():
    # A query whose only integer is ToInt of a real was QF_NRA, where cvc5 refuses to_int.
    x, y = z3.Reals("x y")
    q = smtlib_query([x * y >= 2, y > 0], z3.ToReal(z3.ToInt(x * y)) >= 0)
    assert q.logic == "QF_NIRA"
    with Cvc5Worker() as w:
        assert w.check(q.text).answer == "unsat"
        wrong = q.text.replace("(set-logic QF_NIRA)", "(set-logic QF_NRA)")
        assert "to_int" in w.check(wrong).reason  # the seeded fault: the old logic choice


@needs_cvc5
def test_a_run_records_which_solvers_confirm_each_vc():
    ob = next(o for o in Z3_OBS if o.id == "Def1.segment")
    pr = discharge(ob)
    assert pr.verdict is Verdict.PROVED
    assert all(v.solvers == ("z3", "cvc5") and v.cvc5 == "unsat" for v in pr.vcs)
    assert pr.solvers == ("z3", "cvc5")
    assert "(set-logic" in pr.standard and "lambda" not in pr.standard


class _Liar:
    """A second solver that answers sat to everything: a disagreement on every proved VC."""

    def submit(self, text: str, strategy: str = "justification") -> Future:
        f: Future = Future()
        f.set_result(Cvc5Answer("sat", ""))
        return f


def test_a_disagreement_between_the_solvers_fails_the_obligation():
    ob = next(o for o in Z3_OBS if o.id == "Prop2.endpoints")
    pr = discharge_pending(ob, _Liar()).settle()
    assert pr.verdict is Verdict.FAILED and "disagree" in pr.reason
    assert pr.vcs[0].solvers == ("z3",) and pr.vcs[0].cvc5 == "sat"


def test_the_convex_norm_certificate_is_an_exact_identity():
    ob = next(o for o in Z3_OBS if o.id == "Lemma.sweep_margin")
    vc = next(v for v in ob.build().vcs if v.name == "convex_norm")
    ok, what = check_certificate(vc)
    assert ok, what
    # Seeded faults: a coefficient changed, or a term dropped, breaks the identity.
    terms = vc.certificate.terms
    wrong = Certificate((Square(Fraction(2), terms[0].slacks, terms[0].q),) + terms[1:])
    import dataclasses
    assert not check_certificate(dataclasses.replace(vc, certificate=wrong))[0]
    assert not check_certificate(dataclasses.replace(
        vc, certificate=Certificate(terms[:-1])))[0]
    # A certificate cannot prove a false goal: the same terms for e^2/2 fail.
    e = z3.Real("e")
    false_goal = z3.substitute(vc.goal, (e * e, e * e / 2))
    assert not check_certificate(dataclasses.replace(vc, goal=false_goal))[0]


def test_an_sos_certificate_confirms_where_cvc5_does_not():
    x, y = z3.Reals("x y")
    cert = Certificate((Square(Fraction(1), (), x - y),))
    vc = VC("amgm", (), 2 * x * y <= x * x + y * y, certificate=cert)

    class _Unknown:
        def submit(self, text: str, strategy: str = "justification") -> Future:
            f: Future = Future()
            f.set_result(Cvc5Answer("unknown", "timeout"))
            return f
    ob = Obligation("T.sos", "t", "r", "s", Method.Z3, Verdict.PROVED, lambda: Z3Query((vc,)))
    pr = discharge_pending(ob, _Unknown()).settle()
    assert pr.verdict is Verdict.PROVED and pr.vcs[0].solvers == ("z3", "sympy-sos")
