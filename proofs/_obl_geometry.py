"""Obligations on the paper's geometry: Definitions 1-3, Lemmas 1-2, separation and distance.

Sets of points are predicates (Z3 arrays), the convex hull is the intersection of all convex
supersets (Definition 3). Z3 cannot guess which superset to instantiate that intersection at,
so where a proof needs one the obligation names it (its statement says so) and Z3 checks the
rest; instantiating a universal hypothesis is sound.
"""

from __future__ import annotations

from fractions import Fraction

import z3

from ..spec.z3defs import (
    POINT_SET,
    convex_instance,
    hull_instance,
    hull_member,
    is_convex,
    segment_member,
    segment_member_paper,
    subset,
)
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._z3vec import vec as _vec

__all__ = ["geometry_obligations"]

GROUP_DEFS = "Definitions 1-3, Lemmas 1-2"
GROUP_SEP = "Separation and distance"


def _set(name: str) -> z3.ArrayRef:
    return z3.Const(name, POINT_SET)


def _plane(value: bool) -> z3.ArrayRef:
    u, v = z3.Reals("pl!u pl!v")
    return z3.Lambda([u, v], z3.BoolVal(value))


def _left_half() -> z3.ArrayRef:
    u, v = z3.Reals("lh!u lh!v")
    return z3.Lambda([u, v], u <= 0)


def _def1() -> Z3Query:
    x, y, z = _vec("x"), _vec("y"), _vec("z")
    t = z3.Real("t")
    return Z3Query((
        # Witness weights t = 1 and t = 0 named: x and y themselves lie on segment x y.
        VC("endpoints", (), z3.And(segment_member(x, y, x, z3.RealVal(1)),
                                   segment_member(x, y, y, z3.RealVal(0)))),
        # Witness 1 - t named: the same point seen from the other end.
        VC("symmetric", (("z on segment x y with weight t", segment_member(x, y, z, t)),),
           segment_member(y, x, z, 1 - t), key_premise="z on segment x y with weight t"),
        VC("degenerate", (("z on segment x x", segment_member(x, x, z, t)),),
           z3.And(z[0] == x[0], z[1] == x[1]), key_premise="z on segment x x"),
    ))


def _frac(v: z3.ExprRef) -> Fraction:
    r = v.as_fraction() if z3.is_rational_value(v) else Fraction(str(v))
    return Fraction(r)


def _def1_paper() -> Z3Query:
    x, y = _vec("x"), _vec("y")
    t = z3.Real("t")

    def render(m: z3.ModelRef) -> str:
        xv = [_frac(m.eval(e)) for e in x]
        yv = [_frac(m.eval(e)) for e in y]
        need = 2 * yv[0] / (xv[0] + yv[0])      # from y.x = t x.x + (t - 1) y.x
        return (f"x = ({xv[0]}, {xv[1]}), y = ({yv[0]}, {yv[1]}): t x + (t - 1) y = y needs "
                f"t = {need}, outside [0, 1], so y is not in the printed segment x y "
                "(with the intended (1 - t) y it is, at t = 0)")
    # The claim "y is on segment x y" for the printed definition, checked at x = (0, 0), y = (1, 0)
    # over every weight t: Z3 shows no t in [0, 1] works.
    pin = (("x = (0, 0)", z3.And(x[0] == 0, x[1] == 0)), ("y = (1, 0)", z3.And(y[0] == 1, y[1] == 0)))
    goal = z3.Exists([t], segment_member_paper(x, y, y, t))
    return Z3Query((VC("contains_y", pin, goal),), render=render)


def _def2() -> Z3Query:
    a, b = _set("A"), _set("B")
    n0, n1, c = z3.Reals("a0 a1 c")
    u, v = z3.Reals("hp!u hp!v")
    half = z3.Lambda([u, v], n0 * u + n1 * v <= c)
    x, y = _vec("x"), _vec("y")
    t = z3.Real("t")
    z = (t * x[0] + (1 - t) * y[0], t * x[1] + (1 - t) * y[1])
    # A ∩ B convex: for arbitrary x, y, t (free names, so all of them), with A's and B's
    # convexity instantiated at those same x, y, t (named).
    return Z3Query((
        VC("halfplane", (), is_convex(half)),
        VC("intersection", (("A convex (at x, y, t)", convex_instance(a, x, y, t)),
                            ("B convex (at x, y, t)", convex_instance(b, x, y, t)),
                            ("x in A ∩ B", z3.And(a[x[0], x[1]], b[x[0], x[1]])),
                            ("y in A ∩ B", z3.And(a[y[0], y[1]], b[y[0], y[1]])),
                            ("0 <= t <= 1", z3.And(0 <= t, t <= 1))),
           z3.And(a[z[0], z[1]], b[z[0], z[1]]), key_premise="B convex (at x, y, t)"),
    ))


def _def3() -> Z3Query:
    x, y = _set("X"), _set("Y")
    p, q, z = _vec("p"), _vec("q"), _vec("z")
    t = z3.Real("t")
    return Z3Query((
        # X ⊆ convex X: the goal is Definition 3 itself, with Z3 skolemising the superset.
        VC("contains", (("p in X", x[p[0], p[1]]),), hull_member(x, p), key_premise="p in X"),
        # convex X ⊆ Y for every convex Y ⊇ X (the hull is the least): instance at Y named.
        VC("least", (("p in convex X (at Y)", hull_instance(x, y, p)), ("Y convex", is_convex(y)),
                     ("X ⊆ Y", subset(x, y))),
           y[p[0], p[1]], key_premise="Y convex", witness=((y, _plane(True)),)),
        # convex X is convex: p, q in convex X and z between them; for an arbitrary convex
        # superset Y of X (a free name, so all of them) z is in Y. Instances named: p and q's
        # membership at Y, and Y's convexity at p, q, t.
        VC("convex", (("Y convex", is_convex(y)), ("X ⊆ Y", subset(x, y)),
                      ("p in convex X (at Y)", hull_instance(x, y, p)),
                      ("q in convex X (at Y)", hull_instance(x, y, q)),
                      ("Y convex (at p, q, t)", convex_instance(y, p, q, t)),
                      ("z on segment p q", segment_member(p, q, z, t))),
           y[z[0], z[1]], key_premise="q in convex X (at Y)", witness=((y, _plane(True)),),
           counter_witness=((y, _left_half()), (x, _plane(False)))),
    ))


def _lemma1() -> Z3Query:
    x, y, z = _set("X"), _set("Y"), _set("Z")
    p = _vec("p")
    # Goal: p in convex Y, at an arbitrary convex superset Z of Y (free, hence all of them);
    # hypothesis p in convex X, instantiated at that same Z (the named witness).
    hyps = (("X ⊆ Y", subset(x, y)), ("p in convex X (at Z)", hull_instance(x, z, p)))
    return Z3Query((VC("monotone", hyps, hull_instance(y, z, p), key_premise="X ⊆ Y",
                       witness=((z, _plane(True)),)),))


def _lemma2() -> Z3Query:
    x, y, z = _set("X"), _set("Y"), _set("Z")
    p = _vec("p")
    u, v = z3.Reals("un!u un!v")
    union = z3.Lambda([u, v], z3.Or(x[u, v], y[u, v]))
    hyps = (("p in convex X or convex Y (at Z)", z3.Or(hull_instance(x, z, p),
                                                        hull_instance(y, z, p))),)
    return Z3Query((VC("union", hyps, hull_instance(union, z, p),
                       key_premise="p in convex X or convex Y (at Z)",
                       witness=((z, _plane(True)),)),))


def _separating_axis() -> Z3Query:
    va, vb = _set("VA"), _set("VB")
    a0, a1, c = z3.Reals("axis.x axis.y c")
    q = _vec("q")
    u, v = z3.Reals("sa!u sa!v")
    below = z3.Lambda([u, v], a0 * u + a1 * v <= c)
    above = z3.Lambda([u, v], a0 * u + a1 * v > c)
    hyps = (("VA on the low side", subset(va, below)), ("VB on the high side", subset(vb, above)))
    # No q lies in both hulls; the hulls are instantiated at the two half-planes (named).
    goal = z3.Not(z3.And(hull_instance(va, below, q), hull_instance(vb, above, q)))
    return Z3Query((VC("disjoint", hyps, goal, key_premise="VB on the high side"),))


def _distance() -> Z3Query:
    a, b, a2, b2 = _set("A"), _set("B"), _set("A'"), _set("B'")
    delta, eps = z3.Reals("delta eps")

    def dist_ge(s: z3.ArrayRef, t: z3.ArrayRef, d: z3.ArithRef) -> z3.BoolRef:
        p0, p1, q0, q1 = z3.Reals("ds!p0 ds!p1 ds!q0 ds!q1")
        return z3.ForAll([p0, p1, q0, q1], z3.Implies(
            z3.And(s[p0, p1], t[q0, q1]), (p0 - q0) ** 2 + (p1 - q1) ** 2 >= d * d))
    p = _vec("p")
    free = (("eps >= 0", eps >= 0), ("delta > eps", delta > eps),
            ("dist(A, B) >= delta", dist_ge(a, b, delta)))
    empty = tuple((x, _plane(False)) for x in (a, b, a2, b2))
    # Pins for the negative test: A empty, B, A' and B' the whole plane (quantified sets are
    # otherwise left to Z3's instantiation heuristics, whose answer varies with term order).
    apart = ((a, _plane(False)), (b, _plane(True)), (a2, _plane(True)), (b2, _plane(True)))
    return Z3Query((
        # The same delta witnesses dist(A', B') > eps: the decision is monotone.
        VC("monotone", free + (("A' ⊆ A", subset(a2, a)), ("B' ⊆ B", subset(b2, b))),
           dist_ge(a2, b2, delta), key_premise="A' ⊆ A", witness=empty, counter_witness=apart),
        VC("sound", free, z3.Not(z3.And(a[p[0], p[1]], b[p[0], p[1]])),
           key_premise="dist(A, B) >= delta", witness=empty[:2],
           counter_witness=((a, _plane(True)), (b, _plane(True)))),
    ))


def geometry_obligations() -> list[Obligation]:
    """Definitions 1-3, Lemmas 1-2, the separating-axis lemma and the distance decision."""
    P, R = Verdict.PROVED, Verdict.REFUTED_AS_EXPECTED
    Z = Method.Z3
    return [
        Obligation("Def1.segment", GROUP_DEFS, "Def. 1 segment_def",
                   "Segment x y (read z = t x + (1 - t) y, 0 <= t <= 1) holds x and y "
                   "(weights 1 and 0 named), is symmetric (weight 1 - t named), and segment x x "
                   "is {x}.", Z, P, _def1,
                   definitional="the definition's weights named",
                   summary=("The segment between two points (Definition 1, read as t x + (1 - t) "
                            "y) contains both end points, is the same in either direction, and is "
                            "a single point when its ends coincide.")),
        Obligation("Def1.segment_printed", GROUP_DEFS, "Def. 1 segment_def as printed",
                   "As printed (z = t x + (t - 1) y), segment x y contains y: refuted at "
                   "x = (0, 0), y = (1, 0), where no t in [0, 1] gives y (a typo for (1 - t) y).",
                   Z, R, _def1_paper,
                   summary=("Definition 1 as printed, t x + (t - 1) y, leaves the segment's second "
                            "end point out: shown false with a counterexample (a typo for (1 - t) "
                            "y).")),
        Obligation("Def2.is_convex", GROUP_DEFS, "Def. 2 is_convex_def",
                   "A half-plane {p | a.p <= c} is convex, and the intersection of two convex "
                   "sets is convex.", Z, P, _def2,
                   summary=("A half-plane is convex, and so is the intersection of two convex sets "
                            "(Definition 2).")),
        Obligation("Def3.convex_hull", GROUP_DEFS, "Def. 3 convex_def",
                   "convex X (the intersection of all convex supersets) contains X, lies in every "
                   "convex superset Y of X (instance at Y named), and is convex (for an arbitrary "
                   "convex superset Y, named).", Z, P, _def3,
                   summary=("The convex hull of a set (Definition 3) contains the set, lies inside "
                            "every convex set containing it, and is itself convex.")),
        Obligation("Lemma1.convex_monotone", GROUP_DEFS, "Lemma 1 convex_monotone",
                   "X ⊆ Y implies convex X ⊆ convex Y; the hypothesis p in convex X is "
                   "instantiated at the goal's convex superset Z of Y (witness named).",
                   Z, P, _lemma1,
                   summary="Lemma 1: a larger set has a larger convex hull."),
        Obligation("Lemma2.convex_union", GROUP_DEFS, "Lemma 2 convex_union",
                   "convex X ∪ convex Y ⊆ convex (X ∪ Y); the hypotheses are instantiated at the "
                   "goal's convex superset Z of X ∪ Y (witness named).", Z, P, _lemma2,
                   summary=("Lemma 2: the hulls of two sets together lie inside the hull of the "
                            "two sets' union.")),
        Obligation("Sep.separating_axis", GROUP_SEP, "docs/model.md §4 (intersection test)",
                   "If every vertex of A has a.p <= c and every vertex of B has a.p > c, the convex "
                   "hulls of the two vertex sets share no point (any vertex sets, any axis a; the "
                   "hulls instantiated at the two half-planes, named).", Z, P, _separating_axis,
                   summary=("Two polygons whose corners lie strictly on opposite sides of a line "
                            "share no point.")),
        Obligation("Sep.distance_monotone", GROUP_SEP, "docs/model.md §4 (free iff distance > eps)",
                   "If dist(A, B) >= delta > eps >= 0 then A and B share no point, and "
                   "dist(A', B') >= delta for A' ⊆ A, B' ⊆ B: the distance-based free decision "
                   "is sound and monotone under containment (same delta named).", Z, P, _distance,
                   summary=("Declaring two regions apart when their distance exceeds a tiny "
                            "threshold is sound, and stays sound for any smaller regions inside "
                            "them.")),
    ]
