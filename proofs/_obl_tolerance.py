"""The tolerance tube of a certified trajectory (docs/model.md §12): c > 2 L delta implies no contact.

Distances are over the reals, as squares: a norm n of a vector v is a real with n >= 0 and
n^2 = v.x^2 + v.y^2, so Z3 needs no square root. Three VCs:

- ``triangle``: |x + y| <= |x| + |y| (Cauchy-Schwarz in squares);
- ``speed``: a link point's velocity w1 J(p - base) + w2 J(p - elbow) (J the quarter turn) has
  length <= |w1| R_base + |w2| R_elbow when |p - base| <= R_base and |p - elbow| <= R_elbow;
- ``tube``: planned points p (left link), q (right link) at distance >= c, their deviated
  positions p', q' within L delta of them, and c > 2 L delta: then p' != q' (the triangle
  inequality at the two named instances it needs).
"""

from __future__ import annotations

import z3

from ._obl_groups import GROUP_TUBE
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._z3vec import abs_ as _abs
from ._z3vec import norm as _norm
from ._z3vec import sub as _sub
from ._z3vec import vec as _vec

__all__ = ["GROUP", "KEY_PREMISE", "tolerance_obligations"]

GROUP = GROUP_TUBE
#: The tube lemma's key premise (the negative test drops or weakens it).
KEY_PREMISE = "c > 2 L delta"


def _triangle() -> VC:
    x, y = _vec("x"), _vec("y")
    nx, ny, nxy = z3.Reals("|x| |y| |x+y|")
    return VC("triangle", (("|x| >= 0 and |x|^2 = x.x", _norm(nx, x)),
                           ("|y| is the length of y", _norm(ny, y)),
                           ("|x + y| is the length of x + y",
                            _norm(nxy, (x[0] + y[0], x[1] + y[1])))),
              nxy <= nx + ny, key_premise="|x| >= 0 and |x|^2 = x.x")


def _speed() -> VC:
    p, base, elbow = _vec("p"), _vec("base"), _vec("elbow")
    w1, w2, rb, re_, na, nb, nv = z3.Reals("w1 w2 R_base R_elbow |p-base| |p-elbow| |v|")
    a, b = _sub(p, base), _sub(p, elbow)
    # J(x, y) = (-y, x), the quarter turn: dp/dtheta1 = J(p - base), dp/dtheta2 = J(p - elbow).
    v = (-w1 * a[1] - w2 * b[1], w1 * a[0] + w2 * b[0])
    return VC("speed", (("|p - base| is its length", _norm(na, a)),
                        ("|p - elbow| is its length", _norm(nb, b)),
                        ("|v| is the velocity's length", _norm(nv, v)),
                        ("|p - base| <= R_base", na <= rb),
                        ("|p - elbow| <= R_elbow", nb <= re_)),
              nv <= _abs(w1) * rb + _abs(w2) * re_, key_premise="|p - base| <= R_base")


def tube_vc(premise: z3.BoolRef | None = None) -> VC:
    """The tube VC; ``premise`` replaces c > 2 L delta (the negative test weakens it)."""
    p, q, pp, qp = _vec("p"), _vec("q"), _vec("p'"), _vec("q'")
    c, lip, delta = z3.Reals("c L delta")
    d_pq, d_ppp, d_qqp, d_pqp, d_ppqp = z3.Reals("|p-q| |p-p'| |q-q'| |p-q'| |p'-q'|")
    key = c > 2 * lip * delta if premise is None else premise
    return VC("tube", (
        ("|p - q| is its length", _norm(d_pq, _sub(p, q))),
        ("|p - p'| is its length", _norm(d_ppp, _sub(p, pp))),
        ("|q - q'| is its length", _norm(d_qqp, _sub(q, qp))),
        ("|p - q'| is its length", _norm(d_pqp, _sub(p, qp))),
        ("|p' - q'| is its length", _norm(d_ppqp, _sub(pp, qp))),
        ("|p - q| >= c (the proved clearance)", d_pq >= c),
        ("|p - p'| <= L delta (left deviation)", d_ppp <= lip * delta),
        ("|q - q'| <= L delta (right deviation)", d_qqp <= lip * delta),
        (KEY_PREMISE, key),
        ("triangle at p, p', q'", d_pqp <= d_ppp + d_ppqp),
        ("triangle at p, q', q", d_pq <= d_pqp + d_qqp),
    ), z3.Not(z3.And(pp[0] == qp[0], pp[1] == qp[1])), key_premise=KEY_PREMISE,
        # For the vacuity check: p = p' = (0, 0), q = q' = (1, 0), c = L = 1, delta = 1/10.
        witness=tuple((v, z3.RealVal(x)) for v, x in (
            (p[0], 0), (p[1], 0), (pp[0], 0), (pp[1], 0), (q[0], 1), (q[1], 0), (qp[0], 1),
            (qp[1], 0), (c, 1), (lip, 1), (delta, "1/10"), (d_pq, 1), (d_ppp, 0), (d_qqp, 0),
            (d_pqp, 1), (d_ppqp, 1))))


def _query() -> Z3Query:
    return Z3Query((_triangle(), _speed(), tube_vc()))


def tolerance_obligations() -> list[Obligation]:
    """Tolerance.tube: the certified tube of docs/model.md §12."""
    return [
        Obligation("Tolerance.tube", GROUP, "docs/model.md §12 (tolerance tube)",
                   "A motion within delta (max norm over the four joints) of a trajectory proved "
                   "clear by c has no contact when c > 2 L delta, L the largest R_base + R_elbow "
                   "over both arms' links: the triangle inequality (in squares); a link point's "
                   "velocity w1 J(p - base) + w2 J(p - elbow) has length <= |w1| R_base + "
                   "|w2| R_elbow; and planned points at distance >= c whose deviated positions "
                   "are within L delta of them do not meet (triangle inequality at the two named "
                   "instances). Prose, not checked: integrating the speed bound along the "
                   "joint-space segment from the planned to the deviated configuration gives "
                   "|p - p'| <= delta (R_base + R_elbow) <= L delta.",
                   Method.Z3, Verdict.PROVED, _query,
                   summary=("A robot that tracks a plan proved clear by c to within delta in every "
                            "joint cannot collide while c > 2 L delta, L the largest reach of a "
                            "link about its two joints (metres per radian).")),
    ]
