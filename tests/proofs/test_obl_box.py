"""Thm3.box_nesting: the encoding is the spec's box rules, and breaking the s_q rule is caught."""

from __future__ import annotations

import z3

from cfmpa.proofs._obl_builtdr import _box_nesting


def _answer(hyps, goal) -> z3.CheckSatResult:
    s = z3.Solver()
    s.set("timeout", 10_000)
    s.add([h for _, h in hyps])
    s.add(z3.Not(goal))
    return s.check()


def test_box_nesting_is_proved_and_needs_the_sign_rule():
    outer, inner = _box_nesting().vcs
    assert _answer(outer.hypotheses, outer.goal) == z3.unsat
    assert _answer(inner.hypotheses, inner.goal) == z3.unsat
    # The modified box pointing away from the goal (s_q = -1 always): the tight box escapes.
    g0, s0 = z3.Reals("goal start")
    wrong = z3.substitute(inner.goal, (z3.If(g0 > s0, z3.RealVal(1), z3.RealVal(-1)),
                                       z3.RealVal(-1)))
    assert not z3.eq(wrong, inner.goal)
    assert _answer(inner.hypotheses, wrong) == z3.sat


def test_the_boxes_agree_with_spec_left_box_on_a_scenario():
    # The Z3 rules evaluated at a real layer give the intervals spec.left_box computes.
    from pathlib import Path

    from cfmpa.spec import load_scenario
    from cfmpa.spec._grid import left_angles, left_box
    s = load_scenario(Path(__file__).resolve().parents[2] / "scenarios" / "default.toml")
    k, q = 3, 0
    a0 = float(left_angles(s, k * s.dt)[q])
    a1 = float(left_angles(s, (k + 1) * s.dt)[q])
    w = s.left.omega[q] * s.dt
    sign = 1.0 if s.left.goal[q] > s.left.start[q] else -1.0
    assert left_box(s, "original", k)[q] == (a0 - w, a0 + w)
    assert left_box(s, "modified", k)[q] == (min(a0, a0 + sign * w), max(a0, a0 + sign * w))
    assert left_box(s, "tight", k)[q] == (min(a0, a1), max(a0, a1))
