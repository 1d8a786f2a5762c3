"""Negative tests: every Z3 encoding fails once a premise is broken, so none is true for a
trivial reason; planted bugs in BuiltDR's loop nest are caught."""

from __future__ import annotations

import pytest
import z3

from cfmpa.proofs import Method, Verdict, collect_obligations, discharge
from cfmpa.proofs._obl_builtdr import _query as builtdr_query
from cfmpa.proofs._obligation import VC, Obligation

PROVED_Z3 = [o for o in collect_obligations(scenarios_dir="/nonexistent")
             if o.method is Method.Z3 and o.expected is Verdict.PROVED]


def _answer(vc: VC) -> z3.CheckSatResult:
    ctx = z3.Context()
    s = z3.Solver(ctx=ctx)
    s.set("timeout", 20_000)
    s.add([h.translate(ctx) for _, h in vc.hypotheses])
    s.add(z3.Not(vc.goal.translate(ctx)))
    # Pins under which Z3 finds the counter-model (e.g. a convex set it cannot invent).
    s.add([c.translate(ctx) == v.translate(ctx) for c, v in vc.counter_witness])
    return s.check()


@pytest.mark.parametrize("ob", PROVED_Z3, ids=lambda o: o.id)
def test_dropping_the_key_premise_makes_z3_answer_sat(ob: Obligation):
    vcs = [vc for vc in ob.build().vcs if vc.key_premise is not None]
    assert vcs, f"{ob.id} has no VC with a key premise, so no negative test"
    # Loop-heavy obligations have many VCs of one shape; a few suffice to show the point.
    for vc in vcs[:4]:
        broken = vc.without(vc.key_premise)
        assert _answer(broken) == z3.sat, f"{ob.id}/{vc.name} without {vc.key_premise!r}"


@pytest.mark.parametrize("bug,vc", [("inner_bound", "C.i.preserve"),
                                    ("store_value", "C.j.preserve"),
                                    ("weak_invariant", "C.i.preserve"),
                                    ("rest_layer", "D.j.preserve")])
def test_planted_builtdr_bugs_are_refuted(bug: str, vc: str):
    correct = {v.name: v for v in builtdr_query("original", "correctness").vcs}
    buggy = {v.name: v for v in builtdr_query("original", "correctness", bug).vcs}
    N, m, n = z3.Ints("N m n")
    # A small grid: Z3 finds the counter-model at once there, and one suffices.
    small = ((N, z3.IntVal(2)), (m, z3.IntVal(2)), (n, z3.IntVal(2)))
    pin = lambda v: VC(v.name, v.hypotheses, v.goal, counter_witness=small)  # noqa: E731
    assert _answer(pin(correct[vc])) == z3.unsat
    assert _answer(pin(buggy[vc])) == z3.sat


def test_a_buggy_builtdr_fails_its_obligation():
    ob = Obligation("T.bug", "test", "none", "buggy BuiltDR", Method.Z3, Verdict.PROVED,
                    lambda: builtdr_query("original", "correctness", "rest_layer"))
    pr = discharge(ob)
    assert pr.verdict is Verdict.FAILED and pr.counterexample
    assert "D.j.preserve" in {r.name for r in pr.vcs if r.answer == "sat"}


def test_the_fixed_is_path_closes_the_printed_gap():
    # The refuted Def4.is_path_printed hypotheses with the fixed is_path added: now unsat.
    from cfmpa.proofs._obl_paths import _def4_printed, _setting
    from cfmpa.spec._z3defs import is_path_fixed, z3_path
    vc = _def4_printed().vcs[0]
    st = _setting()
    fixed = is_path_fixed(st.P, st.d, st.start, st.goal, z3_path("L"))
    strengthened = VC(vc.name, vc.hypotheses + (("fixed is_path", fixed),), vc.goal)
    assert _answer(vc) == z3.sat
    assert _answer(strengthened) == z3.unsat
