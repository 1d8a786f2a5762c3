"""Negative tests: every Z3 encoding fails once a premise is broken, so none is true for a
trivial reason; planted bugs in BuiltDR's loop nest are caught.

Every VC of every Z3 obligation expected proved is covered: a VC with hypotheses loses its key
premise and Z3 must answer sat; the few VCs without hypotheses, or whose goal does not depend on
them (For-loop termination's entry VCs), are named below and tested another way.
"""

from __future__ import annotations

import pytest
import z3

from cfmpa.proofs import Method, Verdict, collect_obligations, discharge
from cfmpa.proofs._obl_builtdr import _query as builtdr_query
from cfmpa.proofs._obligation import VC, Obligation
from z3answer import answer

PROVED_Z3 = [o for o in collect_obligations(scenarios_dir="/nonexistent")
             if o.method is Method.Z3 and o.expected is Verdict.PROVED]
ALL_VCS = [(o.id, vc) for o in PROVED_Z3 for vc in o.build().vcs]

#: VCs with no hypotheses at all: their goal is a closed formula, tested by perturbing it.
NO_HYPOTHESES = {("Def1.segment", "endpoints"), ("Def2.is_convex", "halfplane")}
#: VCs whose goal holds without their hypotheses: the entry VC of a termination proof (a For
#: loop's counter starts at lo, within [lo, max(lo, hi)]); the statement says it is syntactic.
SYNTACTIC = {(ident, f"BuiltDR.{v}.main") for ident, v in (
    ("Thm1.termination", "original"), ("Thm3.termination", "modified"),
    ("Thm3.termination_tight", "tight"))}


def _answer(vc: VC, goal: z3.BoolRef | None = None) -> z3.CheckSatResult:
    # Pins under which Z3 finds the counter-model (e.g. a convex set it cannot invent).
    return answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal if goal is None else goal)]
                  + [c == v for c, v in vc.counter_witness])


KEYED = [(i, vc) for i, vc in ALL_VCS if (i, vc.name) not in NO_HYPOTHESES | SYNTACTIC]


def test_every_vc_is_keyed_or_named_as_an_exception():
    unkeyed = {(i, vc.name) for i, vc in ALL_VCS if vc.key_premise is None}
    assert unkeyed == NO_HYPOTHESES | SYNTACTIC
    assert {(i, vc.name) for i, vc in ALL_VCS if not vc.hypotheses} == NO_HYPOTHESES
    assert len(KEYED) >= 130         # the loop nests' VCs are all in (135 today), not a sample


@pytest.mark.parametrize("ident,vc", KEYED, ids=[f"{i}/{vc.name}" for i, vc in KEYED])
def test_dropping_the_key_premise_makes_z3_answer_sat(ident: str, vc: VC):
    # (That the VC itself is unsat is the full run's business: test_runner.)
    broken = vc.without(vc.key_premise)
    assert _answer(broken) == z3.sat, f"{ident}/{vc.name} without {vc.key_premise!r}"


def _vc(ident: str, name: str) -> VC:
    return next(vc for i, vc in ALL_VCS if i == ident and vc.name == name)


def test_closed_goals_are_not_true_for_a_trivial_reason():
    from cfmpa.spec.z3defs import is_convex, segment_member
    x = (z3.Real("x.x"), z3.Real("x.y"))
    y = (z3.Real("y.x"), z3.Real("y.y"))
    one, zero = z3.RealVal(1), z3.RealVal(0)
    ends = _vc("Def1.segment", "endpoints")
    # The goal is what the test rebuilds, and with the weights swapped it is refuted.
    assert z3.eq(ends.goal, z3.And(segment_member(x, y, x, one), segment_member(x, y, y, zero)))
    assert _answer(ends) == z3.unsat
    assert _answer(ends, z3.And(segment_member(x, y, x, zero),
                                segment_member(x, y, y, one))) == z3.sat
    half = _vc("Def2.is_convex", "halfplane")
    assert _answer(half) == z3.unsat
    assert z3.is_quantifier(half.goal)
    # is_convex is not valid of every set: two disjoint strips are refuted.
    u, v = z3.Reals("u v")
    assert _answer(half, is_convex(z3.Lambda([u, v], z3.Or(u <= 0, u >= 1)))) == z3.sat


@pytest.mark.parametrize("ident,name", sorted(SYNTACTIC))
def test_termination_entry_vcs_are_syntactic_as_the_statement_says(ident: str, name: str):
    vc = _vc(ident, name)
    ob = next(o for o in PROVED_Z3 if o.id == ident)
    assert "syntactic" in ob.statement
    assert _answer(VC(vc.name, (), vc.goal)) == z3.unsat


@pytest.mark.parametrize("ident", ["Thm2.searchoptpath", "Thm4.searchoptpath",
                                   "Thm4.searchoptpath_tight"])
def test_search_theorems_need_theorem_1s_postcondition(ident: str):
    # The key premise is the whole precondition; drop only its last conjunct, BuiltDR's
    # postcondition (sizes and the endpoints in the grid stay).
    (main,) = [vc for i, vc in ALL_VCS if i == ident]
    ((name, pre),) = main.hypotheses
    assert name == "pre" and z3.is_and(pre) and pre.num_args() == 4
    weak = VC(main.name, (("pre without BuiltDR's postcondition", z3.And(pre.children()[:3])),),
              main.goal)
    assert _answer(weak) == z3.sat


def test_tight_search_needs_its_own_rest_layer():
    # Theorem 4 (tight) with the rest layer built from layer N-1 (the paper's) instead of the
    # principal at rest: the safety it promises from step N on is no longer implied.
    from cfmpa.proofs._obl_paths import _search_post, _setting, search_top_level
    from cfmpa.proofs._while import verification_conditions
    from cfmpa.spec.z3defs import REGION, blocked_exact, in_grid, inter, z3_path
    st = _setting()
    found, R = z3.Bool("found"), z3_path("R")
    ints = z3.IntSort()
    region_l = z3.Function("regionL_tight", ints, REGION)
    region_r = z3.Function("regionR", ints, ints, REGION)
    program, no_path = search_top_level(st, found, R)

    def motion(k, i, j):
        return inter(region_l(k), region_r(i, j))

    def paper_rest(_, i, j):
        return inter(region_l(st.d.N - 1), region_r(i, j))
    pre = z3.And(st.d.sane(), in_grid(st.d, st.start), in_grid(st.d, st.goal),
                 blocked_exact(st.P, st.d, motion=motion, rest=paper_rest))
    post = _search_post(st, found, R, no_path, "tight", printed=True)
    main = verification_conditions("wrong_rest", pre, program, post)[0]
    one = z3.IntVal(1)
    small = ((st.d.N, one), (st.d.m, one), (st.d.n, one))   # the counter-model is found at once
    assert _answer(VC(main.name, main.hypotheses, main.goal, counter_witness=small)) == z3.sat


# The program is extracted from the loop form (cfmpa.impl.builtdr_loop_nest) and its invariants
# generated from it, so a bug planted in the source keeps the loops consistent and fails the
# triple (.main); only the weakened invariant, a defect of the proof, fails a preservation VC.
@pytest.mark.parametrize("bug,vc", [("inner_bound", "BuiltDR.original.main"),
                                    ("store_value", "BuiltDR.original.main"),
                                    ("weak_invariant", "C.i.preserve"),
                                    ("rest_layer", "BuiltDR.original.main")])
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
                    lambda: builtdr_query("original", "correctness", "inner_bound"))
    pr = discharge(ob)
    assert pr.verdict is Verdict.FAILED and pr.counterexample
    assert "BuiltDR.original.main" in {r.name for r in pr.vcs if r.answer == "sat"}


def test_the_fixed_is_path_closes_the_printed_gap():
    # The refuted Def4.is_path_printed hypotheses with the fixed is_path added: now unsat.
    from cfmpa.proofs._obl_paths import _def4_printed, _setting
    from cfmpa.spec.z3defs import is_path_fixed, z3_path
    vc = _def4_printed().vcs[0]
    st = _setting()
    fixed = is_path_fixed(st.P, st.d, st.start, st.goal, z3_path("L"))
    strengthened = VC(vc.name, vc.hypotheses + (("fixed is_path", fixed),), vc.goal)
    assert _answer(vc) == z3.sat
    assert _answer(strengthened) == z3.unsat


def test_the_fixed_is_path_keeps_the_list_in_the_grid():
    # Def4.is_path_printed_off_grid's hypotheses with the fixed is_path added: now unsat.
    from cfmpa.proofs._obl_paths import _def4_off_grid, _setting
    from cfmpa.spec.z3defs import is_path_fixed, z3_path
    vc = _def4_off_grid().vcs[0]
    st = _setting()
    fixed = is_path_fixed(st.P, st.d, st.start, st.goal, z3_path("L"))
    assert _answer(vc) == z3.sat
    assert _answer(VC(vc.name, vc.hypotheses + (("fixed is_path", fixed),), vc.goal)) == z3.unsat
