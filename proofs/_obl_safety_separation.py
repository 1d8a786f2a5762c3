"""Part (d) of the end-to-end safety theorem (docs/model.md §10), ``Safety.separation``: a pair
BuiltDR frees (float distance > eps) is at an exact distance > 0 when the float value is within
spec.DISTANCE_ERROR_M of the exact one (ledger A12) and that bound is below eps; regions at a
positive distance hold links that share no point.
"""

from __future__ import annotations

import z3

from ..spec import (
    DISTANCE_ERROR_M,
    EPS,
)
from ..spec.z3defs import (
    REGION,
    member,
)
from ._lemmas import Lemma, lemma
from ._z3vec import (
    Vec,
)
from ._z3vec import vec as _v

_R = z3.RealSort()
#: spec.EPS as the rational its decimal literal denotes.
EPS_Q = z3.RealVal(repr(EPS))

# --- (d) separation ------------------------------------------------------------------------------

_LINK_L = z3.Function("linkL", z3.IntSort(), _R, _R, _R, _R, z3.BoolSort())
_LINK_R = z3.Function("linkR", z3.IntSort(), _R, _R, _R, _R, z3.BoolSort())


def link_l(a: z3.ArithRef, theta: Vec, p: Vec) -> z3.BoolRef:
    """p is a point of the principal's link a (0, 1) at configuration theta."""
    return _LINK_L(a, theta[0], theta[1], p[0], p[1])


def link_r(b: z3.ArithRef, theta: Vec, p: Vec) -> z3.BoolRef:
    """p is a point of the subordinate's link b (0, 1) at configuration theta."""
    return _LINK_R(b, theta[0], theta[1], p[0], p[1])


def apart(A: z3.ExprRef, B: z3.ExprRef, eps: z3.ArithRef) -> z3.BoolRef:
    """Every point of A is more than eps from every point of B."""
    x1, y1, x2, y2 = z3.Reals("ap!x1 ap!y1 ap!x2 ap!y2")
    return z3.ForAll([x1, y1, x2, y2], z3.Implies(
        z3.And(member(A, (x1, y1)), member(B, (x2, y2))),
        (x1 - x2) * (x1 - x2) + (y1 - y2) * (y1 - y2) > eps * eps))


#: fdist(A, B): the distance of two regions as BuiltDR computes it in doubles (or the lower
#: bound it compares: a box gap, a separating-axis gap); dist(A, B): the exact distance.
_FDIST = z3.Function("fdist", REGION, REGION, _R)
_DIST = z3.Function("dist", REGION, REGION, _R)
#: spec.DISTANCE_ERROR_M as the rational its decimal literal denotes.
ERR_Q = z3.RealVal(repr(DISTANCE_ERROR_M))
EPS_HYP = "eps = spec.EPS"
ERR_HYP = "err = spec.DISTANCE_ERROR_M"


def float_free(A: z3.ExprRef, B: z3.ExprRef, eps: z3.ArithRef) -> z3.BoolRef:
    """BuiltDR's free test on a pair of regions: the float distance exceeds eps."""
    return _FDIST(A, B) > eps


def rounding(A: z3.ExprRef, B: z3.ExprRef, err: z3.ArithRef) -> z3.BoolRef:
    """Ledger A12 at (A, B): the float distance is within err of the exact one."""
    return z3.And(_FDIST(A, B) - _DIST(A, B) <= err, _DIST(A, B) - _FDIST(A, B) <= err)


def distance_meaning(A: z3.ExprRef, B: z3.ExprRef) -> z3.BoolRef:
    """What a positive distance of compact regions means: no point of A is a point of B."""
    return z3.Implies(_DIST(A, B) > 0, apart(A, B, z3.RealVal(0)))


def separation_lemmas() -> tuple[Lemma, Lemma]:
    """(d): (eps_margin) with the float distance within err of the exact one (A12) and err =
    spec.DISTANCE_ERROR_M <= eps = spec.EPS, a cell freed on "float distance > eps" has
    regions at an exact distance > 0 (refuted for any eps below err); (no_common_point) regions
    at a positive distance hold links that share no point."""
    A, B = z3.Consts("sep.A sep.B", REGION)
    eps, err = z3.Reals("eps err")
    key = "A12: |fdist(A, B) - dist(A, B)| <= err"
    hyps = ((EPS_HYP, eps == EPS_Q), (ERR_HYP, err == ERR_Q), (key, rounding(A, B, err)),
            ("BuiltDR frees the pair: fdist(A, B) > eps", float_free(A, B, eps)))
    margin = lemma("eps_margin", hyps, _DIST(A, B) > 0, key, names=dict(A=A, B=B))
    a, b = z3.Ints("sep.a sep.b")
    tl, tr, p = _v("sep.thetaL"), _v("sep.thetaR"), _v("sep.p")
    key2 = "dist(A, B) > 0"
    hyps2 = ((key2, _DIST(A, B) > 0), ("the distance of compact regions", distance_meaning(A, B)),
             ("(c) link a of the principal at theta_L lies in A (at p)",
              z3.Implies(link_l(a, tl, p), member(A, p))),
             ("(c) link b of the subordinate at theta_R lies in B (at p)",
              z3.Implies(link_r(b, tr, p), member(B, p))))
    goal = z3.Not(z3.And(link_l(a, tl, p), link_r(b, tr, p)))
    common = lemma("no_common_point", hyps2, goal, key2,
                   names=dict(A=A, B=B, a=a, b=b, thetaL=tl, thetaR=tr, p=p))
    return margin, common
