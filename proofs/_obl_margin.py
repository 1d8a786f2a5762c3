"""Obligations on swept regions (docs/model.md §4): the interpolation margin, and the naive hull.

sin and cos are not in Z3's language; they enter as real unknowns constrained by facts stated
in the obligation (and in the ledger): c^2 + s^2 = 1, cos x >= 1 - x^2/2 for every real x, cos
even and non-increasing on [0, pi], sin >= 0 and cos >= 0 on [0, pi/2]. Coordinates are chosen
with the pivot at the origin and the arc symmetric about the x-axis: rigid motions preserve
distances and segments, so this loses nothing.
"""

from __future__ import annotations

import sympy as sp
import z3

from ._obligation import (VC, CheckOutcome, CheckQuery, Method, Obligation, Verdict, Z3Query,
                          check_source)

__all__ = ["margin_obligations"]

GROUP = "Swept regions (docs/model.md §4)"

#: A rational below pi: the lemma is stated for turns g <= 157/50 (3.14) rad; lattice spacings
#: are of the order of omega dt, a few hundredths.
G_MAX = z3.Q(157, 50)

Vec = tuple[z3.ArithRef, z3.ArithRef]


def _n2(v: Vec) -> z3.ArithRef:
    return v[0] * v[0] + v[1] * v[1]


def _sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1])


def _add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1])


def _comb(a: Vec, b: Vec, lam: z3.ArithRef) -> Vec:
    return ((1 - lam) * a[0] + lam * b[0], (1 - lam) * a[1] + lam * b[1])


def _vec(name: str) -> Vec:
    return z3.Real(f"{name}.x"), z3.Real(f"{name}.y")


def _arc_chord() -> Z3Query:
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
    return Z3Query((VC("arc_within_chord", facts, goal,
                       key_premise="cos(psi) >= cos(g/2) as |psi| <= g/2 <= pi"),))


def _sweep_margin() -> Z3Query:
    """Composition: the two one-joint bounds add (docs/model.md §4, impl ``sweep_margin``).

    Setting: p is a link point at (theta1, theta2) in the lattice cell [c1, c1 + g1] x
    [c2, c2 + g2]; a = p(c1, theta2), b = p(c1 + g1, theta2); p00 .. p11 its corner positions.
    The arc lemma about the base gives |p - h1| <= e_base with h1 = (1 - lam) a + lam b on the
    chord; about the elbow, at each end, |a - a'| <= e_elbow with a' = (1 - mu) p00 + mu p01 and
    |b - b'| <= e_elbow with b' = (1 - nu) p10 + nu p11. Goal: h = (1 - lam) a' + lam b' lies in
    the hull of the four corners and |p - h| <= e_base + e_elbow.
    """
    e, e1, e2, lam, mu, nu = z3.Reals("e e1 e2 lam mu nu")
    x, y = _vec("x"), _vec("y")
    # Step lemmas over free (universally quantified) names, with |v|^2 as the polynomial.
    convex_norm = VC("convex_norm", (("e >= 0", e >= 0), ("|x| <= e", _n2(x) <= e * e),
                                     ("|y| <= e", _n2(y) <= e * e),
                                     ("0 <= lam <= 1", z3.And(0 <= lam, lam <= 1))),
                     _n2(_comb(x, y, lam)) <= e * e, key_premise="|y| <= e")
    triangle = VC("triangle", (("e1 >= 0", e1 >= 0), ("e2 >= 0", e2 >= 0),
                               ("|x| <= e1", _n2(x) <= e1 * e1), ("|y| <= e2", _n2(y) <= e2 * e2)),
                  _n2(_add(x, y)) <= (e1 + e2) * (e1 + e2), key_premise="|y| <= e2")
    r, big, g = z3.Reals("r R g")
    reach = VC("reach", (("0 <= r <= R", z3.And(0 <= r, r <= big)), ("g >= 0", g >= 0)),
               r * g * g / 8 <= big * g * g / 8, key_premise="0 <= r <= R")

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
    same = z3.And(*[z3.simplify(u) == z3.simplify(v) for u, v in zip(_add(d1, d2), _sub(p, h))])
    identity = VC("identity", weights, z3.And(in_hull, same), key_premise="0 <= lam, mu, nu <= 1")

    # The glue treats |v|^2 as an uninterpreted sq(v): valid for every sq, so for the
    # polynomial, under which the step-lemma instances among its hypotheses are true.
    sq = z3.Function("sq", z3.RealSort(), z3.RealSort(), z3.RealSort())

    def sqv(v: Vec) -> z3.ArithRef:
        return sq(v[0], v[1])

    def inst(vc: VC, pairs: list[tuple[z3.ExprRef, z3.ExprRef]]) -> z3.BoolRef:
        """The proved step lemma vc with its free names replaced, |v|^2 written sq(v)."""
        body = z3.Implies(z3.And([f for _, f in vc.hypotheses]), vc.goal)
        return _abstract_norms(z3.substitute(body, *pairs), sq)

    nonneg = VC("nonneg", (("r >= 0", r >= 0),), r * g * g / 8 >= 0, key_premise="r >= 0")
    sa, sb, sm = z3.Reals("sq_s sq_a sq_b")
    square_mono = VC("square_monotone", (("0 <= a", 0 <= sa), ("a <= b", sa <= sb),
                                         ("s <= a^2", sm <= sa * sa)),
                     sm <= sb * sb, key_premise="a <= b")
    # The margins are the lemma's: e_base = R_base g1^2/8, e_elbow = R_elbow g2^2/8, reached
    # from Margin.arc_chord's bound at each point's own radius (r1 about the base, r2a and r2b
    # about the elbow at the two ends) through the reach and square_monotone step lemmas.
    e1v, e2v = z3.Reals("e_base e_elbow")
    g1, g2, rb, re_ = z3.Reals("g1 g2 R_base R_elbow")
    r1, r2a, r2b = z3.Reals("r1 r2a r2b")
    arc = lambda rad, turn: rad * turn * turn / 8  # noqa: E731 - Margin.arc_chord's bound

    def bound(d: Vec, rad: z3.ArithRef, turn: z3.ArithRef, reach_max: z3.ArithRef,
              e_: z3.ArithRef, where: str) -> tuple[tuple[str, z3.BoolRef], ...]:
        return (
            (f"Margin.arc_chord at {where}: |.| <= r g^2/8", sqv(d) <= arc(rad, turn) * arc(rad, turn)),
            (f"reach at {where}", inst(reach, [(r, rad), (big, reach_max), (g, turn)])),
            (f"square_monotone at {where}", inst(square_mono, [
                (sa, arc(rad, turn)), (sb, e_), (sm, sqv(d))])),
            (f"nonneg at {where}", inst(nonneg, [(r, rad), (g, turn)])))
    glue = (
        ("e_base = R_base g1^2/8, e_elbow = R_elbow g2^2/8",
         z3.And(e1v == arc(rb, g1), e2v == arc(re_, g2))),
        ("0 <= g1, g2 <= 3.14", z3.And(0 <= g1, g1 <= G_MAX, 0 <= g2, g2 <= G_MAX)),
        ("0 <= r1 <= R_base; 0 <= r2a, r2b <= R_elbow",
         z3.And(0 <= r1, r1 <= rb, 0 <= r2a, r2a <= re_, 0 <= r2b, r2b <= re_)),
        ("e_base, e_elbow >= 0", z3.And(e1v >= 0, e2v >= 0)),
        ("0 <= lam <= 1", z3.And(0 <= lam, lam <= 1)),
        *bound(d1, r1, g1, rb, e1v, "the base (p - h1)"),
        *bound(d_a, r2a, g2, re_, e2v, "the elbow at a (a - a')"),
        *bound(d_b, r2b, g2, re_, e2v, "the elbow at b (b - b')"),
        ("convex_norm at (a - a', b - b')", inst(convex_norm, [
            (e, e2v), (x[0], d_a[0]), (x[1], d_a[1]), (y[0], d_b[0]), (y[1], d_b[1])])),
        ("triangle at (p - h1, lam-combination of a - a', b - b')", inst(triangle, [
            (e1, e1v), (e2, e2v), (x[0], d1[0]), (x[1], d1[1]), (y[0], d2[0]), (y[1], d2[1])])),
        ("identity", same),
    )
    delta = e1v + e2v
    compose = VC("compose", glue, sqv(_sub(p, h)) <= delta * delta,
                 key_premise="Margin.arc_chord at the base (p - h1): |.| <= r g^2/8")
    return Z3Query((convex_norm, triangle, reach, nonneg, square_mono, identity, compose))


def _abstract_norms(f: z3.ExprRef, sq: z3.FuncDeclRef) -> z3.ExprRef:
    """f with every u*u + v*v (as _n2 builds it) replaced by sq(u, v)."""
    if z3.is_add(f) and f.num_args() == 2:
        l, r = f.arg(0), f.arg(1)
        if (z3.is_mul(l) and z3.is_mul(r) and l.num_args() == 2 and r.num_args() == 2
                and z3.eq(l.arg(0), l.arg(1)) and z3.eq(r.arg(0), r.arg(1))):
            return sq(l.arg(0), r.arg(0))
    if z3.is_app(f) and f.num_args() > 0:
        kids = [_abstract_norms(c, sq) for c in f.children()]
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
                   Method.SYMPY, P, _cos_bound),
        Obligation("Margin.arc_chord", GROUP, "docs/model.md §4 (margin lemma, one joint)",
                   "A point at distance r from a pivot, turning through an angle in [0, g], "
                   "g <= 3.14, stays within r g^2/8 of the chord between its end positions "
                   "(within r (1 - cos(g/2)) of its projection on the chord, which lies on it); "
                   "pivot at the origin, arc symmetric about the x-axis (no loss: rigid motions); "
                   "sin, cos as real unknowns with the ledger's facts (A3); nearest point named.",
                   Method.Z3, P, _arc_chord),
        Obligation("Lemma.sweep_margin", GROUP, "docs/model.md §4 (margin lemma, two joints)",
                   "A link point at (theta1, theta2) in a lattice cell [c1, c1+g1] x [c2, c2+g2] "
                   "is within delta = g1^2/8 R_base + g2^2/8 R_elbow of the hull of its four "
                   "corner positions: the base arc's chord point and the elbow arcs' chord points "
                   "combine (norm convex, triangle inequality, radius monotone, r g^2/8 >= 0, "
                   "squares monotone; each step a VC, used through named instances). The compose "
                   "VC ties e_base = R_base g1^2/8 and e_elbow = R_elbow g2^2/8 to Margin.arc_chord's "
                   "bound r g^2/8 at each point's radius (r1 <= R_base, r2 <= R_elbow). Prose, "
                   "not checked: that Margin.arc_chord, proved with the pivot at the origin and "
                   "the arc symmetric about the x-axis, holds for an arc about any pivot in any "
                   "position (rigid motions, ledger A3), and that its chord point is the one at "
                   "weight lam (the lemma gives some weight; lam names it).",
                   Method.Z3, P, _sweep_margin),
        Obligation("Margin.naive_hull", GROUP, "docs/model.md §4 (paper's corner hull)",
                   "The hull of a link at its end configurations contains it in between: refuted "
                   "exactly (sympy) for a segment turning by pi/2, whose tip at pi/4 has a "
                   "negative barycentric coordinate.", Method.SYMPY, R, _naive_hull),
    ]
