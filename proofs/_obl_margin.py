"""Obligations on swept regions (docs/model.md §4): the interpolation margin, and the naive hull.

sin and cos are not in Z3's language; they enter as real unknowns constrained by facts stated
in the obligation (and in the ledger): c^2 + s^2 = 1, cos x >= 1 - x^2/2 for every real x, cos
even and non-increasing on [0, pi], sin >= 0 and cos >= 0 on [0, pi/2]. Margin.arc_chord is
stated with the pivot at the origin and the arc symmetric about the x-axis; Lemma.sweep_margin
places it by a rigid motion (a rotation (C, S) with C^2 + S^2 = 1, then a translation) at each
of its three arcs, and what the motion preserves (the norm, the chord point) is proved there
(the rotation and frame VCs), not assumed. The constant r g^2/8 is Margin.arc_chord's, proved
from the facts above; the lemma's margins are compared with it, so another constant fails.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import sympy as sp
import z3

from ._obligation import (
    VC,
    CheckOutcome,
    CheckQuery,
    Method,
    Obligation,
    Verdict,
    Z3Query,
    check_source,
)
from ._sos import Certificate, Square
from ._z3vec import G_MAX, Vec
from ._z3vec import add as _add
from ._z3vec import comb as _comb
from ._z3vec import n2 as _n2
from ._z3vec import rot as _rot
from ._z3vec import sub as _sub
from ._z3vec import vec as _vec

__all__ = ["margin_obligations"]

GROUP = "Swept regions (docs/model.md §4)"

# The lemma is stated for turns g <= G_MAX, the loader's spacing bound (spec.MAX_SPACING,
# 157/50 = 3.14 rad, read; below pi: Safety.*.composition's spacing_below_pi); lattice spacings
# are of the order of omega dt, a few hundredths.


@dataclass(frozen=True)
class _Arc:
    """Margin.arc_chord's VC and the terms of its statement (over its free names r, g, c, s,
    c_psi, s_psi): the point m, its end positions a and b, the chord weight t, the chord point
    q = (1 - t) a + t b and the bound delta = r g^2/8."""

    vc: VC
    names: tuple[z3.ArithRef, ...]
    m: Vec
    a: Vec
    b: Vec
    t: z3.ArithRef
    q: Vec
    delta: z3.ArithRef


def _arc() -> _Arc:
    r, g, c, s, cp, sp_ = z3.Reals("r g c s c_psi s_psi")
    half = g / 2
    # c = cos(g/2), s = sin(g/2); c_psi, s_psi = cos, sin of the point's angle psi, |psi| <= g/2.
    facts = (
        ("r >= 0", r >= 0),
        ("0 <= g <= 3.14", z3.And(0 <= g, g <= G_MAX)),
        ("c^2 + s^2 = 1", c * c + s * s == 1),
        ("c_psi^2 + s_psi^2 = 1", cp * cp + sp_ * sp_ == 1),
        ("cos(g/2) >= 1 - (g/2)^2/2", c >= 1 - half * half / 2),
        ("cos(psi) >= cos(g/2) as |psi| <= g/2 <= pi", cp >= c),
        ("sin(g/2) >= 0 as 0 <= g/2 <= pi", s >= 0),
        ("cos(g/2) >= 0 as 0 <= g/2 <= pi/2", c >= 0),
    )
    m = (r * cp, r * sp_)                   # the rotating point
    a, b = (r * c, -r * s), (r * c, r * s)  # its end positions
    # The nearest chord point, named: (r c, r s_psi) at weight t (any t when the chord is a point).
    t = z3.If(s > 0, (sp_ + s) / (2 * s), z3.RealVal(0.5))
    q = _comb(a, b, t)
    delta = r * g * g / 8
    goal = z3.And(0 <= t, t <= 1, _n2(_sub(m, q)) <= delta * delta)
    vc = VC("arc_within_chord", facts, goal,
            key_premise="cos(psi) >= cos(g/2) as |psi| <= g/2 <= pi")
    return _Arc(vc, (r, g, c, s, cp, sp_), m, a, b, t, q, delta)


def _arc_chord() -> Z3Query:
    return Z3Query((_arc().vc,))


def _place(o: Vec, cs: Vec, v: Vec) -> Vec:
    """The rigid motion: v turned by cs, then moved to o."""
    return _add(o, _rot(cs, v))


def _sweep_margin() -> Z3Query:
    """Composition: the two one-joint bounds add (docs/model.md §4, impl ``sweep_margin``).

    Setting: p is a link point at (theta1, theta2) in the lattice cell [c1, c1 + g1] x
    [c2, c2 + g2]; a = p(c1, theta2), b = p(c1 + g1, theta2); p00 .. p11 its corner positions.
    Three arcs: p turns about the base from a to b (turn g1); a turns about the elbow from p00
    to p01, b from p10 to p11 (turn g2). Each arc is Margin.arc_chord's, placed by a rigid
    motion (a rotation (C, S) with C^2 + S^2 = 1, then a translation o): its point, ends and
    chord point are the lemma's m, a, b, q, turned and moved. Margin.arc_chord's instance at
    each arc bounds the canonical |m - q| by r g^2/8 (the lemma's own bound, at the arc's radius
    and turn), the rotation step lemma carries the bound to the placed arc, and the frame step
    lemma identifies the placed difference with the chord defect: |p - h1| for h1 = (1 - t_b) a
    + t_b b, |a - a'| for a' = (1 - t_a) p00 + t_a p01, |b - b'| likewise, the weights being the
    lemma's chord weights. Goal: h = (1 - t_b) a' + t_b b' lies in the hull of the four corners
    and |p - h| <= e_base + e_elbow, the lemma's margins R_base g1^2/8 and R_elbow g2^2/8: a
    margin below what the arcs need (another constant) is refuted.
    """
    arc = _arc()
    e, e1, e2, lam, mu, nu = z3.Reals("e e1 e2 lam mu nu")
    x, y = _vec("x"), _vec("y")
    # Step lemmas over free (universally quantified) names, with |v|^2 as the polynomial.
    convex_norm = VC("convex_norm", (("e >= 0", e >= 0), ("|x| <= e", _n2(x) <= e * e),
                                     ("|y| <= e", _n2(y) <= e * e),
                                     ("0 <= lam <= 1", z3.And(0 <= lam, lam <= 1))),
                     _n2(_comb(x, y, lam)) <= e * e, key_premise="|y| <= e",
                     certificate=_convex_norm_certificate(e, x, y, lam),
                     # Z3's default solver (nlsat, its variables reordered) took 11.6 M resource
                     # units, 2.5 s, the prove's costliest check, and 5-57 M or unknown under
                     # other nlsat seeds; nlsat in the declared order takes 0.74 M, 0.16 s,
                     # under every seed tried (docs/model.md §6.1).
                     z3_tactic="qfnra-nlsat", z3_tactic_params=(("reorder", False),))
    triangle = VC("triangle", (("e1 >= 0", e1 >= 0), ("e2 >= 0", e2 >= 0),
                               ("|x| <= e1", _n2(x) <= e1 * e1), ("|y| <= e2", _n2(y) <= e2 * e2)),
                  _n2(_add(x, y)) <= (e1 + e2) * (e1 + e2), key_premise="|y| <= e2")
    r, big, g = z3.Reals("r R g")
    d_at = lambda rad, turn: z3.substitute(  # noqa: E731 - Margin.arc_chord's bound
        arc.delta, (arc.names[0], rad), (arc.names[1], turn))
    reach = VC("reach", (("0 <= r <= R", z3.And(0 <= r, r <= big)), ("g >= 0", g >= 0)),
               d_at(r, g) <= d_at(big, g), key_premise="0 <= r <= R")
    nonneg = VC("nonneg", (("r >= 0", r >= 0),), d_at(r, g) >= 0, key_premise="r >= 0")
    sa, sb, sm = z3.Reals("sq_s sq_a sq_b")
    square_mono = VC("square_monotone", (("0 <= a", 0 <= sa), ("a <= b", sa <= sb),
                                         ("s <= a^2", sm <= sa * sa)),
                     sm <= sb * sb, key_premise="a <= b")
    # The rigid motions: a rotation keeps |v|, and a placed point minus the placed chord point
    # is the canonical difference, turned.
    cs = tuple(z3.Reals("C S"))
    v = _vec("v")
    unit = cs[0] * cs[0] + cs[1] * cs[1] == 1
    rotation = VC("rotation", (("C^2 + S^2 = 1", unit),), _n2(_rot(cs, v)) == _n2(v),
                  key_premise="C^2 + S^2 = 1")
    o, mv, av, bv, xw, y0, y1 = (_vec(n) for n in ("o", "m", "A", "B", "X", "Y0", "Y1"))
    tv = z3.Real("t")
    placed = z3.And(*[z3.And(u[0] == w[0], u[1] == w[1]) for u, w in (
        (xw, _place(o, cs, mv)), (y0, _place(o, cs, av)), (y1, _place(o, cs, bv)))])
    defect = _sub(xw, _comb(y0, y1, tv))
    turned = _rot(cs, _sub(mv, _comb(av, bv, tv)))
    frame = VC("frame", (("X, Y0, Y1 = o + rot(m), o + rot(A), o + rot(B)", placed),),
               z3.And(defect[0] == turned[0], defect[1] == turned[1]),
               key_premise="X, Y0, Y1 = o + rot(m), o + rot(A), o + rot(B)")

    p, a, b = _vec("p"), _vec("a"), _vec("b")
    k00, k01, k10, k11 = _vec("p00"), _vec("p01"), _vec("p10"), _vec("p11")
    a2, b2 = _comb(k00, k01, mu), _comb(k10, k11, nu)
    h1, h = _comb(a, b, lam), _comb(a2, b2, lam)
    d_a, d_b = _sub(a, a2), _sub(b, b2)
    d1, d2 = _sub(p, h1), _comb(d_a, d_b, lam)
    w = ((1 - lam) * (1 - mu), (1 - lam) * mu, lam * (1 - nu), lam * nu)
    corners = (k00, k01, k10, k11)
    weights = (("0 <= lam, mu, nu <= 1",
                z3.And(0 <= lam, lam <= 1, 0 <= mu, mu <= 1, 0 <= nu, nu <= 1)),)
    in_hull = z3.And(*[wi >= 0 for wi in w], z3.Sum(w) == 1,
                     h[0] == z3.Sum([wi * k[0] for wi, k in zip(w, corners)]),
                     h[1] == z3.Sum([wi * k[1] for wi, k in zip(w, corners)]))
    same = z3.And(*[u == v_ for u, v_ in zip(_add(d1, d2), _sub(p, h))])
    identity = VC("identity", weights, z3.And(in_hull, same), key_premise="0 <= lam, mu, nu <= 1")

    # The glue treats |v|^2 as an uninterpreted sq(v): valid for every sq, so for the
    # polynomial, under which the step-lemma instances among its hypotheses are true.
    sq = z3.Function("sq", z3.RealSort(), z3.RealSort(), z3.RealSort())

    def inst(vc: VC, pairs: list[tuple[z3.ExprRef, z3.ExprRef]]) -> z3.BoolRef:
        """The proved step lemma vc with its free names replaced, |v|^2 written sq(v)."""
        body = z3.Implies(z3.And([f for _, f in vc.hypotheses]), vc.goal)
        return _abstract_norms(z3.substitute(body, *pairs), sq)

    def pairs(*groups: tuple[z3.ExprRef | tuple[z3.ExprRef, ...], z3.ExprRef | tuple[z3.ExprRef, ...]]
              ) -> list[tuple[z3.ExprRef, z3.ExprRef]]:
        out: list[tuple[z3.ExprRef, z3.ExprRef]] = []
        for name, term in groups:
            out += list(zip(name, term)) if isinstance(name, tuple) else [(name, term)]
        return out

    e1v, e2v = z3.Reals("e_base e_elbow")
    g1, g2, rb, re_ = z3.Reals("g1 g2 R_base R_elbow")
    glue: list[tuple[str, z3.BoolRef]] = [
        # The lemma's margins: what impl.sweep_margin must cover (Scenario.*.margin_side).
        ("e_base = R_base g1^2/8, e_elbow = R_elbow g2^2/8",
         z3.And(e1v == rb * g1 * g1 / 8, e2v == re_ * g2 * g2 / 8)),
        ("0 <= g1, g2 <= 3.14", z3.And(0 <= g1, g1 <= G_MAX, 0 <= g2, g2 <= G_MAX)),
        ("e_base, e_elbow >= 0", z3.And(e1v >= 0, e2v >= 0)),
    ]
    geo: list[tuple[str, z3.BoolRef]] = []      # the arcs VC's hypotheses
    bounds: list[z3.BoolRef] = []               # ... and its conclusions, one per arc
    weight: dict[str, z3.ArithRef] = {}
    defects: dict[str, Vec] = {}
    for tag, turn, reach_max, e_, (xw_, y0_, y1_) in (
            ("base", g1, rb, e1v, (p, a, b)), ("elbow_a", g2, re_, e2v, (a, k00, k01)),
            ("elbow_b", g2, re_, e2v, (b, k10, k11))):
        # The arc's own names: radius, cos/sin of half its turn and of the point's angle, the
        # rotation placing it and its pivot.
        rad, c_, s_, cp_, sp_ = z3.Reals(f"r_{tag} c_{tag} s_{tag} cpsi_{tag} spsi_{tag}")
        rc = tuple(z3.Reals(f"C_{tag} S_{tag}"))
        piv = _vec(f"o_{tag}")
        sig = list(zip(arc.names, (rad, turn, c_, s_, cp_, sp_)))
        sub = lambda f_, sig=sig: z3.substitute(f_, *sig)  # noqa: E731
        m_, a_, b_, q_ = ((sub(u[0]), sub(u[1])) for u in (arc.m, arc.a, arc.b, arc.q))
        t_ = sub(arc.t)
        weight[tag] = t_
        mq = _sub(m_, q_)
        defects[tag] = _sub(xw_, _comb(y0_, y1_, t_))
        bounds.append(z3.And(0 <= t_, t_ <= 1,
                             sq(*defects[tag]) <= d_at(rad, turn) * d_at(rad, turn)))
        geo += [
            (f"A3 facts at the {tag} arc (Margin.arc_chord's premises)", _abstract_norms(
                z3.substitute(z3.And([f for _, f in arc.vc.hypotheses]), *sig), sq)),
            (f"Margin.arc_chord at the {tag} arc", inst(arc.vc, sig)),
            (f"the {tag} arc placed: C^2 + S^2 = 1", _abstract_norms(
                rc[0] * rc[0] + rc[1] * rc[1] == 1, sq)),
            (f"the {tag} arc placed: its point and ends", z3.And(*[
                z3.And(u[0] == w_[0], u[1] == w_[1]) for u, w_ in (
                    (xw_, _place(piv, rc, m_)), (y0_, _place(piv, rc, a_)),
                    (y1_, _place(piv, rc, b_)))])),
            (f"rotation at the {tag} arc", inst(rotation, pairs((cs, rc), (v, mq)))),
            (f"frame at the {tag} arc", inst(frame, pairs(
                (o, piv), (cs, rc), (mv, m_), (av, a_), (bv, b_), (tv, t_), (xw, xw_),
                (y0, y0_), (y1, y1_)))),
        ]
        glue += [
            (f"0 <= r_{tag} <= R", z3.And(0 <= rad, rad <= reach_max)),
            (f"reach at the {tag} arc", inst(reach, [(r, rad), (big, reach_max), (g, turn)])),
            (f"square_monotone at the {tag} arc", inst(square_mono, [
                (sa, d_at(reach_max, turn)), (sb, e_), (sm, sq(*defects[tag]))])),
            (f"nonneg at the {tag} arc", inst(nonneg, [(r, reach_max), (g, turn)])),
        ]
    # The arcs VC: placed by its rigid motion, each arc's chord defect is within the arc
    # lemma's bound r g^2/8 at the arc's radius and turn, at the arc's chord weight.
    arcs = VC("arcs", tuple(geo), z3.And(bounds), key_premise="Margin.arc_chord at the base arc")
    glue.insert(3, ("the three placed arcs' chord defects (the arcs VC)", z3.And(bounds)))
    # The weights are the arcs' chord weights.
    sig_w = [(lam, weight["base"]), (mu, weight["elbow_a"]), (nu, weight["elbow_b"])]
    d1_, d_a_, d_b_ = defects["base"], defects["elbow_a"], defects["elbow_b"]
    d2_ = _comb(d_a_, d_b_, weight["base"])
    glue += [
        ("convex_norm at (a - a', b - b')", inst(convex_norm, pairs(
            (e, e2v), (x, d_a_), (y, d_b_), (lam, weight["base"])))),
        ("triangle at (p - h1, the combination of a - a', b - b')", inst(triangle, pairs(
            (e1, e1v), (e2, e2v), (x, d1_), (y, d2_)))),
        ("identity", inst(identity, sig_w)),
    ]
    h_ = (z3.substitute(h[0], *sig_w), z3.substitute(h[1], *sig_w))
    goal = z3.And(z3.substitute(in_hull, *sig_w),
                  sq(*_sub(p, h_)) <= (e1v + e2v) * (e1v + e2v))
    compose = VC("compose", tuple(glue), goal,
                 key_premise="the three placed arcs' chord defects (the arcs VC)")
    return Z3Query((convex_norm, triangle, reach, nonneg, square_mono, rotation, frame,
                    identity, arcs, compose))


def _convex_norm_certificate(e: z3.ArithRef, x: Vec, y: Vec, lam: z3.ArithRef) -> Certificate:
    """e^2 - |(1 - lam) x + lam y|^2 = (1 - lam)(e^2 - |x|^2) + lam (e^2 - |y|^2)
    + lam (1 - lam) |x - y|^2, every term a product of hypothesis slacks and a square."""
    one = Fraction(1)
    return Certificate((
        Square(one, (("0 <= lam <= 1", 1), ("|x| <= e", 0))),
        Square(one, (("0 <= lam <= 1", 0), ("|y| <= e", 0))),
        Square(one, (("0 <= lam <= 1", 0), ("0 <= lam <= 1", 1)), x[0] - y[0]),
        Square(one, (("0 <= lam <= 1", 0), ("0 <= lam <= 1", 1)), x[1] - y[1]),
    ), name="SOS certificate of convex_norm")


def _abstract_norms(f: z3.ExprRef, sq: z3.FuncDeclRef,
                    memo: dict[int, z3.ExprRef] | None = None) -> z3.ExprRef:
    """f with every u*u + v*v (as _n2 builds it) replaced by sq(u, v). A subterm shared in f's
    DAG is rewritten once (``memo``, by Z3's id: the rewrite of a term is a function of it)."""
    memo = {} if memo is None else memo
    key = f.get_id()
    if key in memo:
        return memo[key]
    out = _abstract_norms_at(f, sq, memo)
    memo[key] = out
    return out


def _abstract_norms_at(f: z3.ExprRef, sq: z3.FuncDeclRef, memo: dict[int, z3.ExprRef]
                       ) -> z3.ExprRef:
    if z3.is_add(f) and f.num_args() == 2:
        l, r = f.arg(0), f.arg(1)
        if (z3.is_mul(l) and z3.is_mul(r) and l.num_args() == 2 and r.num_args() == 2
                and z3.eq(l.arg(0), l.arg(1)) and z3.eq(r.arg(0), r.arg(1))):
            return sq(l.arg(0), r.arg(0))
    if z3.is_app(f) and f.num_args() > 0:
        kids = [_abstract_norms(c, sq, memo) for c in f.children()]
        return f.decl()(*kids)
    if z3.is_quantifier(f):
        raise ValueError("no quantifiers expected in the margin lemma")
    return f


def _cos_bound() -> CheckQuery:
    x = sp.Symbol("x", real=True)
    f = x ** 2 / 2 - 1 + sp.cos(x)

    def run() -> CheckOutcome:
        d1, d2 = sp.diff(f, x), sp.diff(f, x, 2)
        checks = {
            "f(0) = 0": sp.simplify(f.subs(x, 0)) == 0,
            "f'(x) = x - sin x": sp.simplify(d1 - (x - sp.sin(x))) == 0,
            "f'(0) = 0": sp.simplify(d1.subs(x, 0)) == 0,
            "f''(x) = 1 - cos x": sp.simplify(d2 - (1 - sp.cos(x))) == 0,
            "f even": sp.simplify(f.subs(x, -x) - f) == 0,
        }
        bad = [k for k, ok in checks.items() if not ok]
        if bad:
            return CheckOutcome(False, "failed: " + ", ".join(bad), "; ".join(bad))
        return CheckOutcome(True, "f = x^2/2 - 1 + cos x: f(0) = f'(0) = 0, f'' = 1 - cos x >= 0, "
                            "f even; hence f >= 0 (mean value theorem twice), i.e. "
                            "1 - cos x <= x^2/2")
    return CheckQuery(run, f"f = {sp.srepr(f)}\nchecks: f(0), f', f'(0), f'', evenness\n\n"
                      + check_source(_cos_bound))


def _naive_hull() -> CheckQuery:
    """The arc's midpoint is outside the hull of the segment's two end positions, exactly."""
    def run() -> CheckOutcome:
        o = sp.Matrix([0, 0])
        a = sp.Matrix([1, 0])                            # the link tip at angle 0
        b = sp.Matrix([0, 1])                            # ... at angle pi/2
        mid = sp.Matrix([sp.cos(sp.pi / 4), sp.sin(sp.pi / 4)])   # at angle pi/4
        l0, l1, l2 = sp.symbols("l0 l1 l2")
        eqs = list(l0 * o + l1 * a + l2 * b - mid) + [l0 + l1 + l2 - 1]
        sol = sp.solve(eqs, [l0, l1, l2], dict=True)
        if len(sol) != 1:
            return CheckOutcome(None, f"expected one barycentric solution, got {sol}")
        w = sol[0]
        negative = [str(k) for k, v in w.items() if sp.simplify(v).is_negative]
        outside = sp.simplify(mid[0] + mid[1] - 1)       # > 0: beyond the chord x + y = 1
        cex = (f"segment from the pivot (0, 0) to (1, 0) turning by pi/2: its tip at angle pi/4 is "
               f"({sp.nsimplify(mid[0])}, {sp.nsimplify(mid[1])}); barycentric coordinates in the "
               f"hull (triangle) of the end positions: l0 = {sp.simplify(w[l0])}, "
               f"l1 = {sp.simplify(w[l1])}, l2 = {sp.simplify(w[l2])}; l0 < 0, so the point is "
               f"outside, by {sp.simplify(outside / sp.sqrt(2))} beyond the chord")
        if negative and outside.is_positive:
            return CheckOutcome(False, "refuted exactly: a barycentric coordinate is negative", cex)
        return CheckOutcome(True, "the point is inside (unexpected)")
    return CheckQuery(run, "segment (0,0)-(1,0) turning by pi/2, tip at pi/4 vs triangle "
                      "(0,0), (1,0), (0,1); sympy exact barycentric coordinates\n\n"
                      + check_source(_naive_hull))


def margin_obligations() -> list[Obligation]:
    """The interpolation margin lemma (one joint, two joints), the cos bound, the naive hull."""
    P, R = Verdict.PROVED, Verdict.REFUTED_AS_EXPECTED
    return [
        Obligation("Margin.cos_bound", GROUP, "docs/model.md §4 (margin lemma)",
                   "Toward 1 - cos x <= x^2/2 for every real x: sympy checks only identities "
                   "of f = x^2/2 - 1 + cos x: f(0) = 0, f' = x - sin x, f'(0) = 0, "
                   "f'' = 1 - cos x, f(-x) = f(x). The rest is prose, assumed (ledger A3): "
                   "f'' >= 0 as cos <= 1, so by the mean value theorem f' is non-decreasing, "
                   "f' >= 0 on [0, oo) and f >= f(0) = 0 there, and f even gives x < 0.",
                   Method.SYMPY, P, _cos_bound, label="identities checked, inequality assumed",
                   summary=("1 - cos x is at most x^2/2 for every angle x: the calculus identities "
                            "are checked exactly, the mean value theorem step is taken on trust "
                            "(the ledger says so).")),
        Obligation("Margin.arc_chord", GROUP, "docs/model.md §4 (margin lemma, one joint)",
                   "A point at distance r from a pivot, turning through an angle in [0, g], "
                   "g <= 3.14, stays within r g^2/8 of the chord between its end positions "
                   "(within r (1 - cos(g/2)) of its projection on the chord, which lies on it); "
                   "pivot at the origin, arc symmetric about the x-axis (no loss: rigid motions); "
                   "sin, cos as real unknowns with the ledger's facts (A3); nearest point named.",
                   Method.Z3, P, _arc_chord,
                   summary=("A point at distance r from a joint, turning through an angle g of at "
                            "most 3.14 rad, stays within r g^2/8 of the straight line between its "
                            "first and last positions.")),
        Obligation("Lemma.sweep_margin", GROUP, "docs/model.md §4 (margin lemma, two joints)",
                   "A link point at (theta1, theta2) in a lattice cell [c1, c1+g1] x [c2, c2+g2] "
                   "is within delta = g1^2/8 R_base + g2^2/8 R_elbow of the hull of its four "
                   "corner positions. Three arcs: the point turning about the base (turn g1), "
                   "its ends turning about the elbow (turn g2); each is Margin.arc_chord's arc "
                   "placed by a rigid motion (a rotation (C, S), C^2 + S^2 = 1, and a "
                   "translation). The lemma's instance at each arc's radius, turn and angles "
                   "(its A3 premises stated there) bounds the chord defect by r g^2/8, the "
                   "lemma's own constant; the rotation and frame step lemmas carry the bound to "
                   "the placed arc, the weights being the lemma's chord weights; norm convexity "
                   "(also an exact SOS certificate), the triangle inequality, radius "
                   "monotonicity, r g^2/8 >= 0 and monotone squares combine them (each a VC, "
                   "used through named instances, |v|^2 uninterpreted in the glue). The claimed "
                   "margins R_base g1^2/8, R_elbow g2^2/8 enter only as the goal's bound, so a "
                   "smaller constant is refuted. The setting, not proved here: that the link "
                   "point and the corners are such arcs' points at radii at most R_base about "
                   "the base and R_elbow about the elbow (the kinematics of docs/model.md §2).",
                   Method.Z3, P, _sweep_margin,
                   summary=("Anywhere inside a grid cell of joint angles, a link stays within a "
                            "margin of the hull of its positions at the cell's four corners; the "
                            "margin grows with the square of the cell's size.")),
        Obligation("Margin.naive_hull", GROUP, "docs/model.md §4 (paper's corner hull)",
                   "The hull of a link at its end configurations contains it in between: refuted "
                   "exactly (sympy) for a segment turning by pi/2, whose tip at pi/4 has a "
                   "negative barycentric coordinate.", Method.SYMPY, R, _naive_hull,
                   summary=("The paper's hull of a link at its two end positions does not hold the "
                            "link in between: a link turning by 90 degrees leaves it, shown "
                            "exactly.")),
    ]
