"""Depth: the weakest reasoning that proves a VC, measured by running its abstractions."""

from __future__ import annotations

import pytest
import z3

from cfmpa.proofs import Method, Obligation, Verdict, Z3Query, collect_obligations, discharge
from cfmpa.proofs._depth import deepest, vc_depth
from cfmpa.proofs._obligation import VC
from cfmpa.proofs._smtlib import Mode, smtlib_query


def _depth(hyps, goal) -> str:
    return vc_depth(list(hyps), goal)


def test_the_boolean_skeleton_alone_is_propositional():
    x, y = z3.Reals("x y")
    a, b = x * x > y, x + y == 3            # nonlinear atoms: what they mean does not matter
    assert _depth([a, z3.Implies(a, b)], b) == "propositional"
    text = smtlib_query([a, z3.Implies(a, b)], b, Mode.PROPOSITIONAL).text
    assert "|x|" not in text and "|y|" not in text   # every atom abstracted away


def test_arithmetic_without_instantiation_is_ground():
    x = z3.Real("x")
    assert _depth([x > 1], x > 0) == "ground"
    # A universal goal is skolemised (an existential once negated): no instantiation either.
    assert _depth([], z3.ForAll([x], z3.Implies(x > 1, x > 0))) == "ground"


def test_a_hypothesis_used_at_an_instance_is_full():
    x = z3.Int("x")
    f = z3.Function("f", z3.IntSort(), z3.IntSort())
    every = z3.ForAll([x], f(x) > 0)
    assert _depth([every], f(3) > 0) == "full"
    # The seeded fault: a ground check that left the quantifier to Z3 (no abstraction) would
    # call this ground; the abstraction is what makes it full.
    s = z3.Solver()
    s.from_string(smtlib_query([every], f(3) > 0, Mode.FULL).text)
    assert s.check() == z3.unsat
    s = z3.Solver()
    s.from_string(smtlib_query([every], f(3) > 0, Mode.GROUND).text)
    assert s.check() == z3.sat


def test_the_same_quantifier_twice_is_one_atom():
    x = z3.Int("x")
    f = z3.Function("f", z3.IntSort(), z3.IntSort())
    every = z3.ForAll([x], f(x) > 0)
    goal = z3.BoolVal(True) == every          # Boolean structure over the same formula
    assert _depth([every], goal) == "propositional"


def test_an_obligation_is_as_deep_as_its_deepest_vc():
    assert deepest(["ground", "propositional"]) == "ground"
    assert deepest(["ground", "full", "propositional"]) == "full"
    assert deepest([]) is None
    x = z3.Int("x")
    f = z3.Function("f", z3.IntSort(), z3.IntSort())
    vcs = (VC("p", (("a", x > 1),), x > 0, key_premise="a"),
           VC("q", (("all", z3.ForAll([x], f(x) > 0)),), f(2) > 0, key_premise="all"))
    pr = discharge(Obligation("T.d", "t", "r", "s", Method.Z3, Verdict.PROVED,
                              lambda: Z3Query(vcs)))
    assert pr.verdict is Verdict.PROVED
    assert [v.depth for v in pr.vcs] == ["ground", "full"] and pr.depth == "full"


@pytest.mark.parametrize("ident,level", [("Prop2.endpoints", "propositional"),
                                         ("Prop5.optpath_is_path", "propositional"),
                                         ("Thm1.termination", "ground"),
                                         ("Margin.arc_chord", "ground"),
                                         ("Prop3.layer_free", "full")])
def test_known_depths_of_the_paper_obligations(ident: str, level: str):
    ob = next(o for o in collect_obligations("/nonexistent", [ident]))
    levels = [vc_depth([h for _, h in vc.hypotheses], vc.goal) for vc in ob.build().vcs]
    assert deepest(levels) == level


def test_refutations_and_checks_have_no_depth():
    obs = collect_obligations("/nonexistent", ["Def1.segment_printed", "Margin.naive_hull"])
    for ob in obs:
        assert discharge(ob).depth is None


# --- the nonlinear flag (not what depth measures) ------------------------------------------------

def test_nonlinear_flags_products_and_divisions_of_unknowns():
    from cfmpa.proofs._depth import is_nonlinear

    x, y = z3.Reals("x y")
    assert is_nonlinear([x * y > 0])
    assert is_nonlinear([x / y > 1])
    assert is_nonlinear([z3.ForAll([x], x * x >= y)])           # inside a quantifier too
    assert not is_nonlinear([2 * x + y / 4 > 0, (-x) * 3 <= y])  # constants scale linearly
    assert not is_nonlinear([z3.Real("a") + 1 == y])


def test_results_record_the_flag_per_vc(tmp_path):
    from cfmpa.proofs import VC, Method, Obligation, Verdict, Z3Query, run_obligations

    x, y = z3.Reals("x y")
    ob = Obligation("T.nonlinear", "t", "test", "x y > 0 from x, y > 0", Method.Z3,
                    Verdict.PROVED, lambda: Z3Query((
                        VC("square", (("x > 0", x > 0), ("y > 0", y > 0)), x * y > 0),
                        VC("sum", (("x > 0", x > 0), ("y > 0", y > 0)), x + y > 0))))
    run = run_obligations([ob], tmp_path, ["T.nonlinear"], lock=tmp_path / "lock")
    assert [v.nonlinear for v in run.proofs[0].vcs] == [True, False]
    doc = __import__("json").loads((tmp_path / "results.json").read_text())
    assert [v["nonlinear"] for v in doc["obligations"][0]["vcs"]] == [True, False]
    assert doc["depth"]["nonlinear_vcs"] == 1 and "quantifier" in doc["depth"]["measures"]
