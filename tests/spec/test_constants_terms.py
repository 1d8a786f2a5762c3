"""The constants' formulas restructured to run on Z3 terms give, on floats and on
balls, exactly what the code computed before: reach through hypot_of, the certificate's interval
bound and L_ab, the exact re-decision's separating-axis gap."""

from __future__ import annotations

import math

import numpy as np
import z3
from flint import arb, ctx

import cfmpa.spec as spec
from cfmpa.spec import (
    gap_over_norm,
    hypot_of,
    interval_bound,
    link_speeds,
    pair_lipschitz,
    projection_bounds,
    reach,
    sqrt_of,
)


class _Arm:
    def __init__(self, l1: float, l2: float, w: float) -> None:
        self.links, self.width = (l1, l2), w


def _arms(n: int = 200) -> list[_Arm]:
    rng = np.random.default_rng(7)
    return [_Arm(*(float(x) for x in rng.uniform(0.01, 3.0, 3))) for _ in range(n)]


def test_reach_on_floats_is_the_former_math_hypot_formula_bit_for_bit():
    for arm in _arms():
        r = arm.width / 2
        assert reach(arm, 0) == (math.hypot(arm.links[0] + r, r), 0.0)
        far = math.hypot(arm.links[1] + r, r)
        assert reach(arm, 1) == (arm.links[0] + far, far)


def test_hypot_and_sqrt_on_floats_balls_and_terms():
    assert hypot_of(3.0, 4.0) == math.hypot(3.0, 4.0) and sqrt_of(2.0) == math.sqrt(2.0)
    b = arb(2)
    assert sqrt_of(b).mid() == b.sqrt().mid() and sqrt_of(b).rad() == b.sqrt().rad()
    x = z3.Real("x")
    assert str(sqrt_of(x)) == "x**(1/2)" and "**(1/2)" in str(hypot_of(x, 1))


def test_interval_bound_and_pair_lipschitz_are_the_former_expressions():
    rng = np.random.default_rng(3)
    d0, d1, lip = (rng.uniform(0, 1, (50, 2, 2)) for _ in range(3))
    t0 = rng.uniform(0, 1, 50)
    t1 = t0 + rng.uniform(0, 1e-3, 50)
    old = (d0 + d1 - lip * (t1 - t0)[:, None, None]) / 2.0
    assert np.array_equal(interval_bound(d0, d1, lip, (t1 - t0)[:, None, None]), old)
    vl, vr = rng.uniform(0, 1, (50, 2)), rng.uniform(0, 1, (50, 2))
    assert np.array_equal(pair_lipschitz(vl[:, :, None], vr[:, None, :]),
                          vl[:, :, None] + vr[:, None, :])


def test_link_speeds_runs_on_terms_and_on_floats_alike():
    arm = _Arm(0.5, 0.4, 0.1)
    w = np.array([[0.3, -0.7]])
    on_terms = link_speeds(arm, np.array([[z3.RealVal(0.3), z3.RealVal(-0.7)]], dtype=object))
    floats = link_speeds(arm, w)
    # reach's roots stay roots on the terms: compare after evaluating them numerically.
    for k in range(2):
        v = z3.simplify(on_terms[0, k])
        approx = float(v.approx(20).as_fraction()) if z3.is_algebraic_value(v) else float(
            v.as_fraction())
        assert math.isclose(approx, floats[0, k], rel_tol=1e-12)


def test_the_gap_is_the_former_ball_formula_bit_for_bit():
    rng = np.random.default_rng(11)
    old_prec = ctx.prec
    ctx.prec = 128
    try:
        for _ in range(50):
            # Balls of a small radius, as the corners are.
            a = [(arb(float(x)) + arb(0, 1e-20), arb(float(y)))
                 for x, y in rng.normal(0, 1, (5, 2))]
            b = [(arb(float(x)), arb(float(y)) + arb(0, 1e-20))
                 for x, y in rng.normal(3, 1, (5, 2))]
            nx, ny = (arb(float(v)) for v in rng.normal(0, 1, 2))
            hi_a = max((nx * x + ny * y).upper() for x, y in a)
            lo_b = min((nx * x + ny * y).lower() for x, y in b)
            old = (lo_b - hi_a) / (nx * nx + ny * ny).sqrt()
            new = gap_over_norm(*projection_bounds(nx, ny, a, b), nx, ny)
            assert (new.mid(), new.rad()) == (old.mid(), old.rad())
    finally:
        ctx.prec = old_prec


def test_the_new_names_are_public():
    for name in ("gap_over_norm", "hypot_of", "interval_bound", "link_speeds", "pair_lipschitz",
                 "projection_bounds", "reach", "sqrt_of"):
        assert name in spec.__all__
