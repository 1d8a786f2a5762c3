"""The monitor between samples (docs/model.md §12): the deviation at any instant of a gap is within
``spec.between_samples_bound`` of the deviations sampled at its ends.

One joint, one gap [t_k, t_k+1] of length h: the robot's angle x and the trajectory's r over
the reals, with the speed bounds as the distance each can travel from either end (the robot
moves at most w_x rad/s, the trajectory at most w_r on the gap). The VC ``between_samples``:

    |x(t) - r(t)| <= between_samples_bound(d_k, d_k+1, h, w_x, w_r)

for every t in [t_k, t_k+1], the right-hand side being the spec's very function run on the Z3
terms (``max_of`` is an If there), so a changed bound changes the proved statement. The sampled
deviations are reals d_k >= |x_k - r_k| and each |a| <= b is the case split -b <= a <= b. The
argument Z3 finds is the triangle inequality at either end, |x(t) - r(t)| <= |x(t) - x_k| +
|x_k - r_k| + |r_k - r(t)| <= d_k + (w_x + w_r)(t - t_k), and the same from t_k+1; one of
t - t_k, t_k+1 - t is at most h / 2. Linear in the products w (t - t_k) that Z3 treats as
atoms, with no If but the bound's max, so Z3 decides it at once (with the absolute values as
If terms it answered unknown after 20 s). Prose, not checked: that a speed bound |x'| <= w_x gives
|x(t) - x_k| <= w_x (t - t_k) (the mean value theorem); the four joints are independent, so the
max norm is within the tube when every joint is. That the trajectory's largest speed over the
pieces the gap meets (``spec.ReferenceSpeeds.over``) bounds r' on the gap is
``Monitor.reference_speeds`` (proofs/_obl_wiring.py).

Registered by the proofs' registry (``monitor_obligations``), not by this module.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import z3

from ..spec import between_samples_bound
from ._obligation import VC, Method, Obligation, Verdict, Z3Query

__all__ = ["GROUP", "KEY_PREMISE", "between_samples_vc", "monitor_obligations"]

GROUP = "Trajectories (docs/model.md §12)"
#: The robot's speed bound from the gap's first end (the negative test drops it).
KEY_PREMISE = "|x(t) - x_k| <= w_x (t - t_k)"

Bound = Callable[[Any, Any, Any, Any, Any], Any]


def _within(x: z3.ArithRef, b: z3.ArithRef) -> z3.BoolRef:
    """|x| <= b as its two cases, -b <= x <= b (linear: no If for Z3 to split on)."""
    return z3.And(x <= b, -x <= b)


def between_samples_vc(bound: Bound | None = None) -> VC:
    """The VC with ``bound`` as the claimed bound (default: the spec's
    ``between_samples_bound``; the tests plant a mutated one and see it refuted). The sampled
    deviations are reals d_k >= |x_k - r_k| (what the monitor computes is the equality, a case
    of it), the absolute values two inequalities each."""
    f = between_samples_bound if bound is None else bound
    tk, t, tk1 = z3.Reals("t_k t t_k+1")
    xk, xt, xk1 = z3.Reals("x_k x(t) x_k+1")
    rk, rt, rk1 = z3.Reals("r_k r(t) r_k+1")
    wx, wr, dk, dk1 = z3.Reals("w_x w_r d_k d_k+1")
    claimed = f(dk, dk1, tk1 - tk, wx, wr)
    return VC("between_samples", (
        ("t_k < t_k+1", tk < tk1),
        ("t_k <= t <= t_k+1", z3.And(tk <= t, t <= tk1)),
        ("w_x >= 0 and w_r >= 0", z3.And(wx >= 0, wr >= 0)),
        ("|x_k - r_k| <= d_k", _within(xk - rk, dk)),
        ("|x_k+1 - r_k+1| <= d_k+1", _within(xk1 - rk1, dk1)),
        (KEY_PREMISE, _within(xt - xk, wx * (t - tk))),
        ("|x(t) - x_k+1| <= w_x (t_k+1 - t)", _within(xt - xk1, wx * (tk1 - t))),
        ("|r(t) - r_k| <= w_r (t - t_k)", _within(rt - rk, wr * (t - tk))),
        ("|r(t) - r_k+1| <= w_r (t_k+1 - t)", _within(rt - rk1, wr * (tk1 - t))),
    ), _within(xt - rt, claimed), key_premise=KEY_PREMISE,
        # For the vacuity check: a gap [0, 1], everything at 0 and at rest.
        witness=tuple((v, z3.RealVal(0)) for v in (tk, t, xk, xt, xk1, rk, rt, rk1, wx, wr, dk,
                                                    dk1))
        + ((tk1, z3.RealVal(1)),))


def _query() -> Z3Query:
    return Z3Query((between_samples_vc(),))


def monitor_obligations() -> list[Obligation]:
    """Monitor.between_samples: what `cfmpa monitor` vouches for between two samples."""
    return [
        Obligation("Monitor.between_samples", GROUP, "docs/model.md §12 (monitor between samples)",
                   "Between two samples t_k < t_k+1 (gap h) of one joint, a robot moving at most "
                   "w_x rad/s and a trajectory moving at most w_r on the gap deviate at any "
                   "instant of it by at most max(d_k, d_k+1) + (w_x + w_r) h / 2, d the "
                   "deviations sampled at the ends (spec.between_samples_bound on the terms). "
                   "Prose, not checked: a speed bound gives the distance bound from either end "
                   "(mean value theorem). That w_r, the trajectory's largest speed over the "
                   "pieces the gap meets, bounds its speed there: Monitor.reference_speeds.",
                   Method.Z3, Verdict.PROVED, _query,
                   label="per joint; the speed bounds' integration is prose",
                   summary=("Between two measured samples, a robot and a plan that each move at "
                            "most their speed limit stay within the larger sampled deviation plus "
                            "their speeds times half the gap.")),
    ]
