"""Part (c) of the end-to-end safety theorem (docs/model.md §10), ``Safety.region_soundness``:
a point of a link at any configuration of a box lies in the region built for that box (the
lattice of impl.lattice_range's formula, the link rectangles grown by impl.sweep_margin, their
convex hull), the margin derived from Margin.arc_chord and the snap slack, and compared with the
margin sweep_margin computes (read by running it on Z3 terms). Lemmas enter by substitution
(proofs/_lemmas.py); norm chains are proved for every sq and dt (proofs/_z3vec.py).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import z3

from ..impl import SNAP, lattice_range, link_reach, sweep_margin
from ..spec import (
    Arm,
)
from ._lemmas import Lemma, lemma
from ._obl_arc_chord import ArcChord, arc_chord, arc_steps
from ._obligation import VC, Z3Query
from ._z3vec import COS as _COS
from ._z3vec import (
    DOT,
    G_MAX,
    N2,
    Hyp,
    Vec,
    a3_cos_bound,
    a3_cos_mono,
    a3_cos_nonneg,
    a3_diff,
    a3_sin_nonneg,
    a3_sum,
    a3_unit,
    e,
)
from ._z3vec import SIN as _SIN
from ._z3vec import add as _add
from ._z3vec import comb as _comb
from ._z3vec import diff_rule as _diff_rule
from ._z3vec import occurs as _occurs
from ._z3vec import rot as _rot
from ._z3vec import scale as _scale
from ._z3vec import sub as _sub
from ._z3vec import sum_rule as _sum_rule
from ._z3vec import unit as _unit
from ._z3vec import vec as _v
from ._z3vec import veq as _veq

_R = z3.RealSort()
#: impl.SNAP as the rational its decimal literal denotes.
SNAP_Q = z3.RealVal(repr(SNAP))

# --- the margin impl computes, read symbolically -----------------------------------------------

#: A probe arm: impl.sweep_margin is called with it on symbolic spacings, and its reach values
#: (impl.link_reach) are replaced by symbols; the reading is checked on other arms' floats.
_PROBE = Arm(base=(0.0, 0.0), links=(0.35, 0.3), width=0.06, omega=(1.0, 1.0))
_SAMPLE_ARMS = (_PROBE, Arm(base=(0.6, 0.0), links=(0.5, 0.25), width=0.04, omega=(1.0, 1.0)),
                Arm(base=(-2.0, 1.0), links=(1.3, 0.7), width=0.2, omega=(2.0, 0.5)))
_SAMPLE_G = ((0.02, 0.02), (0.5, 0.01), (3.14, 1.0))


def _q(x: float | Fraction) -> z3.ArithRef:
    f = Fraction(x)
    return z3.RealVal(f"{f.numerator}/{f.denominator}")


def impl_margin_term(link: int, g: Vec, reach: Vec, flags: tuple[bool, bool],
                     margin: Callable[..., object] = sweep_margin) -> z3.ArithRef:
    """``margin(arm, link, g, flags)`` (impl.sweep_margin) for symbolic spacings g and reach
    (R_base, R_elbow): called on the probe arm, its reach numerals replaced by the symbols, and
    checked against the floats ``margin`` gives for sample arms and spacings."""
    rb, re = link_reach(_PROBE, link)
    out = margin(_PROBE, link, g, flags)
    term = (out if isinstance(out, z3.ExprRef)
            else z3.RealVal(repr(float(out))))  # type: ignore[arg-type]
    pairs = [(z3.RealVal(rb), reach[0])] + ([(z3.RealVal(re), reach[1])] if re else [])
    read = z3.substitute(term, *pairs)
    if any(_occurs(z3.RealVal(x), read) for x in (rb, re) if x):
        raise ValueError("the probe's reach survives in the margin read")
    for arm in _SAMPLE_ARMS:
        rb2, re2 = link_reach(arm, link)
        for gg in _SAMPLE_G:
            want = Fraction(float(margin(arm, link, gg, flags)))  # type: ignore[arg-type]
            got = z3.simplify(z3.substitute(read, (g[0], _q(gg[0])), (g[1], _q(gg[1])),
                                            (reach[0], _q(rb2)), (reach[1], _q(re2))))
            if not z3.is_rational_value(got):
                raise ValueError(f"the margin read is not a number at sample inputs: {got}")
            val = got.as_fraction()
            if abs(val - want) > abs(want) * Fraction(1, 10**12):
                raise ValueError(f"the margin read gives {float(val)!r}, sweep_margin "
                                 f"{float(want)!r} for {arm}, link {link}, g = {gg}")
    return read


def impl_margin(link: int, g: Vec, reach: Vec, moving: tuple[z3.BoolRef, z3.BoolRef],
                margin: Callable[..., object] = sweep_margin) -> z3.ArithRef:
    """The margin swept_region grows link ``link``'s rectangles by, for the lattice's moving
    joints (link 1 never moves joint 2: it does not depend on theta2)."""
    def at(f1: bool, f2: bool) -> z3.ArithRef:
        return impl_margin_term(link, g, reach, (f1, f2), margin)
    if link == 0:
        return z3.If(moving[0], at(True, False), at(False, False))
    return z3.If(moving[0], z3.If(moving[1], at(True, True), at(True, False)),
                 z3.If(moving[1], at(False, True), at(False, False)))


# --- (c) region soundness: the construction --------------------------------------------------

@dataclass(frozen=True)
class Lattice:
    """One joint of a box [lo, hi], its lattice anchored at A with spacing g (impl's
    swept_region): the indices impl.lattice_range gives (i_lo, i_hi), whether the lattice has
    more than one point (``moving``), theta clamped onto the lattice's span (theta_c), and the
    lattice cell [c, c + G] holding it: j its first index, G = g if moving, else 0, the far
    corner's index j + step. Each is a name; ``defs`` define them (impl's formulas)."""

    i_lo: z3.ArithRef
    i_hi: z3.ArithRef
    moving: z3.BoolRef
    theta_c: z3.ArithRef
    j: z3.ArithRef
    G: z3.ArithRef
    c: z3.ArithRef
    defs: tuple[Hyp, ...]

    @property
    def step(self) -> z3.ArithRef:
        return z3.If(self.moving, z3.IntVal(1), z3.IntVal(0))

    def names(self) -> dict[str, object]:
        return dict(i_lo=self.i_lo, i_hi=self.i_hi, moving=self.moving, theta_c=self.theta_c,
                    j=self.j, G=self.G, c=self.c)


def lattice(prefix: str, lo: z3.ArithRef, hi: z3.ArithRef, th: z3.ArithRef, A: z3.ArithRef,
            g: z3.ArithRef) -> Lattice:
    i_lo, i_hi, j = z3.Ints(f"{prefix}.i_lo {prefix}.i_hi {prefix}.j")
    moving = z3.Bool(f"{prefix}.moving")
    thc, G, c = z3.Reals(f"{prefix}.theta_c {prefix}.G {prefix}.c")
    # impl.lattice_range itself, run on the symbols: a changed snap or rounding is the proved
    # statement's (a wrong one fails it), not a second copy's.
    lo_t, hi_t = lattice_range(lo, hi, A, g)
    x = (th - A) / g
    lo_r, hi_r = z3.ToReal(i_lo), z3.ToReal(i_hi)
    xc = z3.If(x < lo_r, lo_r, z3.If(x > hi_r, hi_r, x))
    fl = z3.ToInt(xc)
    defs = (
        (f"{prefix}: i_lo, i_hi = impl.lattice_range(lo, hi, A, g)",
         z3.And(i_lo == lo_t, i_hi == hi_t)),
        (f"{prefix}: moving = i_hi > i_lo (more than one lattice point)", moving == (i_hi > i_lo)),
        (f"{prefix}: theta_c = theta clamped onto [A + i_lo g, A + i_hi g]", thc == A + xc * g),
        (f"{prefix}: the cell [c, c + G] of theta_c, j its first index",
         z3.And(j == z3.If(moving, z3.If(fl >= i_hi, i_hi - 1, fl), i_lo),
                G == z3.If(moving, g, z3.RealVal(0)), c == A + z3.ToReal(j) * g)),
    )
    return Lattice(i_lo, i_hi, moving, thc, j, G, c, defs)


def check_lattice_reading() -> None:
    """The model's i_lo, i_hi are impl.lattice_range's, on sample boxes (floats, exactly)."""
    for box, anchor, sp in (((-0.04, 0.04), 0.0, 0.04), ((0.3, 0.32), 0.3, 0.02),
                            ((1.0, 1.0), 1.0, 0.5), ((-1.3, 0.7), 0.25, 0.1),
                            ((0.1 - 1e-12, 0.5 + 1e-12), 0.1, 0.1)):
        L = lattice("chk", _q(box[0]), _q(box[1]), _q(box[0]), _q(anchor), _q(sp))
        s = z3.Solver()
        s.set("timeout", 2000)
        s.add([h for _, h in L.defs])
        if s.check() != z3.sat:
            raise ValueError(f"lattice model undecided at {box, anchor, sp}")
        m = s.model()
        got = (m.eval(L.i_lo).as_long(), m.eval(L.i_hi).as_long())
        want = lattice_range(box[0], box[1], anchor, sp)
        if got != want:
            raise ValueError(f"lattice_range{box, anchor, sp} = {want}, the model gives {got}")


def snap_bound(th: z3.ArithRef, thc: z3.ArithRef, s: z3.ArithRef) -> z3.BoolRef:
    return z3.And(-s <= th - thc, th - thc <= s)


def _wvec_cs(l1: z3.ArithRef, cs: Vec, u: z3.ArithRef, v: z3.ArithRef) -> Vec:
    p = _rot(cs, (u, v))
    return (l1 + p[0], p[1])


def _wvec(l1: z3.ArithRef, beta: z3.ArithRef, u: z3.ArithRef, v: z3.ArithRef) -> Vec:
    """Link 2's point (u, v) seen from the base with theta1 = 0: (l1, 0) + R(beta) (u, v)."""
    return _wvec_cs(l1, e(beta), u, v)


def _elbow_cs(b: Vec, l1: z3.ArithRef, cs: Vec) -> Vec:
    return _add(b, _scale(l1, cs))


def _elbow(b: Vec, l1: z3.ArithRef, alpha: z3.ArithRef) -> Vec:
    return _elbow_cs(b, l1, e(alpha))


def _point2_cs(b: Vec, l1: z3.ArithRef, ca: Vec, cphi: Vec, u: z3.ArithRef,
               v: z3.ArithRef) -> Vec:
    return _add(_elbow_cs(b, l1, ca), _rot(cphi, (u, v)))


def _point2(b: Vec, l1: z3.ArithRef, alpha: z3.ArithRef, phi: z3.ArithRef, u: z3.ArithRef,
            v: z3.ArithRef) -> Vec:
    """docs/model.md §2: the elbow b + l1 e(alpha), then (u, v) in link 2's frame at angle phi
    (phi = alpha + theta2, the absolute angle of link 2)."""
    return _point2_cs(b, l1, e(alpha), e(phi), u, v)


@dataclass(frozen=True)
class BoxPoints:
    """A box of both joints' angles, the lattice cell snapped from it, and the named points of
    link 2's frame point (u, v) that link 2's and the tool's region lemmas chain through: X0 at
    theta, X1 after snapping theta1, X2 after snapping theta2, the chord's ends A, B and the
    cell's corners K0..K3 (``at``: name, alpha, phi, where; ``pts``: each name's vector)."""

    joint1: tuple[z3.ArithRef, ...]        # lo1, hi1, theta1, A1, g1
    joint2: tuple[z3.ArithRef, ...]        # lo2, hi2, theta2, A2, g2
    L1: Lattice
    L2: Lattice
    alphas: tuple[z3.ArithRef, ...]
    phis: tuple[z3.ArithRef, ...]
    at: tuple[tuple[str, z3.ArithRef, z3.ArithRef, str], ...]
    pts: dict[str, Vec]

    @property
    def named(self) -> tuple[Vec, ...]:
        """X0, X1, X2, A, B."""
        return tuple(self.pts[n] for n in ("X0", "X1", "X2", "A", "B"))

    @property
    def corners(self) -> list[Vec]:
        return [self.pts[f"K{i}"] for i in range(4)]

    def lattice_hyps(self, k: dict[str, Lemma]) -> list[Hyp]:
        """Both lattices' definitions and the lattice lemma at each joint."""
        (lo1, hi1, th1, A1, g1), (lo2, hi2, th2, A2, g2) = self.joint1, self.joint2
        return [*self.L1.defs, *self.L2.defs,
                *k["lattice"].at("joint 1", lo=lo1, hi=hi1, theta=th1, A=A1, g=g1,
                                 **self.L1.names()),
                *k["lattice"].at("joint 2", lo=lo2, hi=hi2, theta=th2, A=A2, g=g2,
                                 **self.L2.names())]


def box_points(prefix: str) -> BoxPoints:
    """The box's angles and lattices under ``prefix`` (``prefix.theta1``, ``prefix.joint1``...),
    and the names of link 2's points at them (docs/model.md §4)."""
    joint1 = tuple(z3.Reals(f"{prefix}.lo1 {prefix}.hi1 {prefix}.theta1 {prefix}.A1 {prefix}.g1"))
    joint2 = tuple(z3.Reals(f"{prefix}.lo2 {prefix}.hi2 {prefix}.theta2 {prefix}.A2 {prefix}.g2"))
    L1 = lattice(f"{prefix}.joint1", *joint1)
    L2 = lattice(f"{prefix}.joint2", *joint2)
    th1, th2 = joint1[2], joint2[2]
    t1c, t2c = L1.theta_c, L2.theta_c
    c1, G1, c2, G2 = L1.c, L1.G, L2.c, L2.G
    c1e = c1 + G1
    alphas = (c1, c1, c1e, c1e)
    phis = (c1 + c2, (c1 + c2) + G2, c1e + c2, (c1e + c2) + G2)
    at = [("X0", th1, th1 + th2, "theta"), ("X1", t1c, t1c + th2, "(theta1', theta2)"),
          ("X2", t1c, t1c + t2c, "theta'"), ("A", c1, c1 + t2c, "(c1, theta2')"),
          ("B", c1e, c1e + t2c, "(c1 + G1, theta2')")]
    at += [(f"K{i}", a, ph, f"corner {i}") for i, (a, ph) in enumerate(zip(alphas, phis))]
    pts = {n: _v(f"{prefix}.{n}") for n, *_ in at}
    return BoxPoints(joint1, joint2, L1, L2, alphas, phis, tuple(at), pts)


def grown_coords(phi: z3.ArithRef, u: z3.ArithRef, v: z3.ArithRef, d: Vec) -> Vec:
    """The frame coordinates (at angle phi) of the frame point (u, v) moved by d."""
    c, s = e(phi)
    return (u + (c * d[0] + s * d[1]), v + (-s * d[0] + c * d[1]))


def in_rect(uv: Vec, r: z3.ArithRef, ell: z3.ArithRef) -> z3.BoolRef:
    """(u, v) in the frame of a link of length ell, half-width r, extended by r past both ends."""
    return z3.And(-r <= uv[0], uv[0] <= ell + r, -r <= uv[1], uv[1] <= r)


# --- (c) region soundness: small lemmas, proved on the polynomials ---------------------------

def _rot_norm() -> Lemma:
    c, s = z3.Reals("rn.c rn.s")
    y, z = _v("rn.y"), _v("rn.z")
    key = "z = R(c, s) y"
    return lemma("rot_norm", (("(c, s) on the unit circle", _unit((c, s))),
                              (key, _veq(z, _rot((c, s), y)))), N2(z) == N2(y), key,
                 names=dict(cs=(c, s), y=y, z=z))


def _rot_scale() -> Lemma:
    c, s = z3.Reals("rs.c rs.s")
    y, z = _v("rs.y"), _v("rs.z")
    key = "z = R(c, s) y"
    return lemma("rot_scale", ((key, _veq(z, _rot((c, s), y))),), N2(z) == N2((c, s)) * N2(y),
                 key, names=dict(cs=(c, s), y=y, z=z))


def _scale_norm() -> Lemma:
    c = z3.Real("sn.c")
    y, z = _v("sn.y"), _v("sn.z")
    key = "z = c y"
    return lemma("scale_norm", ((key, _veq(z, _scale(c, y))),), N2(z) == c * c * N2(y), key,
                 names=dict(c=c, y=y, z=z))


def _expand() -> Lemma:
    x, y, z = _v("ex.x"), _v("ex.y"), _v("ex.z")
    key = "z = x + y"
    return lemma("expand", ((key, _veq(z, _add(x, y))),),
                 N2(z) == N2(x) + 2 * DOT(x, y) + N2(y), key, names=dict(x=x, y=y, z=z))


def _dot_bound() -> Lemma:
    x, y = _v("db.x"), _v("db.y")
    a, b = z3.Reals("db.a db.b")
    key = "|y| <= b"
    return lemma("dot_bound", (("a, b >= 0", z3.And(a >= 0, b >= 0)), ("|x| <= a", N2(x) <= a * a),
                               (key, N2(y) <= b * b)), DOT(x, y) <= a * b, key,
                 names=dict(x=x, y=y, a=a, b=b))


def _square_monotone() -> Lemma:
    a, b, m = z3.Reals("sm.a sm.b sm.m")
    key = "a <= b"
    return lemma("square_monotone", (("0 <= a", 0 <= a), (key, a <= b), ("m <= a^2", m <= a * a)),
                 m <= b * b, key, names=dict(a=a, b=b, m=m))


def _proj_id() -> Lemma:
    c, s = z3.Reals("pj.c pj.s")
    d = _v("pj.d")
    key = "(c, s) on the unit circle"
    return lemma("proj_id", ((key, _unit((c, s))),),
                 N2((c * d[0] + s * d[1], -s * d[0] + c * d[1])) == N2(d), key,
                 names=dict(cs=(c, s), d=d))


def _proj_bound() -> Lemma:
    p, q, dl = z3.Reals("pb.p pb.q pb.delta")
    key = "|(p, q)| <= delta"
    return lemma("proj_bound", (("delta >= 0", dl >= 0), (key, N2((p, q)) <= dl * dl)),
                 z3.And(-dl <= p, p <= dl, -dl <= q, q <= dl), key, names=dict(p=p, q=q, delta=dl))


def _grow_id() -> Lemma:
    c, s, u, v = z3.Reals("gi.c gi.s gi.u gi.v")
    J, d = _v("gi.J"), _v("gi.d")
    key = "(c, s) on the unit circle"
    uv2 = (u + (c * d[0] + s * d[1]), v + (-s * d[0] + c * d[1]))
    goal = _veq(_add(_add(J, _rot((c, s), (u, v))), d), _add(J, _rot((c, s), uv2)))
    return lemma("grow_id", ((key, _unit((c, s))),), goal, key,
                 names=dict(cs=(c, s), u=u, v=v, J=J, d=d))


def _chord0() -> Lemma:
    c, sn, x, R, s = z3.Reals("c0.c c0.s c0.x c0.R c0.sbound")
    w = _v("c0.w")
    key = "c >= 1 - x^2/2"
    hyps = (("(c, s) on the unit circle", _unit((c, sn))), (key, c >= 1 - x * x / 2),
            ("-s <= x <= s", z3.And(-s <= x, x <= s)),
            ("|w| <= R", z3.And(R >= 0, N2(w) <= R * R)))
    return lemma("chord0", hyps, N2(_sub(_rot((c, sn), w), w)) <= (s * R) * (s * R), key,
                 names=dict(cs=(c, sn), x=x, R=R, s=s, w=w))


def _chord_id() -> Lemma:
    A, B, X = _v("ci.A"), _v("ci.B"), _v("ci.X")
    o, w = _v("ci.o"), _v("ci.w")
    key = "e(alpha) = e(beta) e(x)"
    goal = _veq(_sub(_add(o, _rot(A, w)), _add(o, _rot(B, w))), _rot(B, _sub(_rot(X, w), w)))
    return lemma("chord_id", ((key, _sum_rule(A, B, X)),), goal, key,
                 names=dict(A=A, B=B, X=X, o=o, w=w))


def _ab(cp: z3.ArithRef, sp: z3.ArithRef, c: z3.ArithRef, s: z3.ArithRef, t: z3.ArithRef) -> Vec:
    """R(psi) - (1 - t) R(-half) - t R(half), a scaled rotation, as its (cos, sin)-like pair."""
    return (cp - ((1 - t) * c + t * c), sp - ((1 - t) * (-s) + t * s))


def _rigid_id() -> Lemma:
    """A point turning about o, minus its chord point at weight t, is R(mid) applied to the
    same difference for the arc at the origin, symmetric about the x-axis (on values: T, S0,
    S1 are e(theta), e(a0), e(a0 + G); M, P, H are e(mid), e(psi), e(G/2))."""
    M, P, H, T, S0, S1 = (_v(f"ri.{n}") for n in ("mid", "psi", "half", "theta", "start", "end"))
    t = z3.Real("ri.t")
    o, w = _v("ri.o"), _v("ri.w")
    key = "e(theta) = e(mid) e(psi)"
    hyps = ((key, _sum_rule(T, M, P)), ("e(a0) = e(mid) e(-G/2)", _diff_rule(S0, M, H)),
            ("e(a0 + G) = e(mid) e(G/2)", _sum_rule(S1, M, H)))
    X, A, B = (_add(o, _rot(cs, w)) for cs in (T, S0, S1))
    goal = _veq(_sub(X, _comb(A, B, t)), _rot(M, _rot(_ab(P[0], P[1], H[0], H[1], t), w)))
    one, zero = z3.RealVal(1), z3.RealVal(0)
    pins = ((T[0], z3.RealVal(2)), (w[0], one), (w[1], zero), (t, zero))
    return lemma("rigid_id", hyps, goal, key, counter_witness=pins,
                 names=dict(M=M, P=P, H=H, T=T, S0=S0, S1=S1, t=t, o=o, w=w))


def _arc_monotone(arc: ArcChord) -> Lemma:
    r, R, G, m = z3.Reals("am.r am.R am.G am.m")
    key = "r^2 <= R^2"
    lo, hi = arc.delta_at(r, G), arc.delta_at(R, G)
    hyps = (("r, R >= 0", z3.And(r >= 0, R >= 0)), (key, r * r <= R * R),
            ("m <= bound(r)^2", m <= lo * lo))
    return lemma("arc_monotone", hyps, m <= hi * hi, key, names=dict(r=r, R=R, G=G, m=m))


def _kin() -> Lemma:
    """docs/model.md §2's link 2 point is the base turned by theta1 of the point at theta1 = 0
    (on values: A, B, AB are e(theta1), e(theta2), e(theta1 + theta2))."""
    A, B, AB = _v("kin.A"), _v("kin.B"), _v("kin.AB")
    l1, u, v = z3.Reals("kin.l1 kin.u kin.v")
    b = _v("kin.b")
    key = "e(theta1 + theta2) = e(theta1) e(theta2)"
    goal = _veq(_add(b, _rot(A, _wvec_cs(l1, B, u, v))), _point2_cs(b, l1, A, AB, u, v))
    return lemma("kin", ((key, _sum_rule(AB, A, B)),), goal, key,
                 names=dict(A=A, B=B, AB=AB, l1=l1, u=u, v=v, b=b))


def _reach_uv(link: int) -> Lemma:
    ell, r, R, u, v = z3.Reals(f"ru{link}.ell ru{link}.r ru{link}.R ru{link}.u ru{link}.v")
    key = f"R = sqrt((l{link + 1} + r)^2 + r^2)"
    hyps = ((f"l{link + 1}, r > 0", z3.And(ell > 0, r > 0)),
            (key, z3.And(R >= 0, R * R == (ell + r) * (ell + r) + r * r)),
            (f"(u, v) in link {link + 1}'s rectangle", in_rect((u, v), r, ell)))
    return lemma(f"reach_uv_link{link + 1}", hyps, N2((u, v)) <= R * R, key,
                 names=dict(ell=ell, r=r, R=R, u=u, v=v))


def _reach_shift() -> Lemma:
    l1, R = z3.Reals("rsh.l1 rsh.R")
    y = _v("rsh.y")
    key = "|y| <= R"
    hyps = (("l1 > 0, R >= 0", z3.And(l1 > 0, R >= 0)), (key, N2(y) <= R * R))
    return lemma("reach_shift", hyps, N2((l1 + y[0], y[1])) <= (l1 + R) * (l1 + R), key,
                 names=dict(l1=l1, R=R, y=y))


def lattice_goal(L: Lattice, th: z3.ArithRef, A: z3.ArithRef, g: z3.ArithRef) -> z3.BoolRef:
    return z3.And(L.i_lo <= L.j, L.j + L.step <= L.i_hi, L.c <= L.theta_c,
                  L.theta_c <= L.c + L.G, L.c + L.G == A + z3.ToReal(L.j + L.step) * g,
                  0 <= L.G, L.G <= g, snap_bound(th, L.theta_c, SNAP_Q * g))


def _lattice() -> tuple[Lemma, Lemma, Lemma]:
    """lattice: the cell of theta_c and theta_c within SNAP g of theta; through lattice_span
    (theta's lattice coordinate (theta - A)/g lies within SNAP of [i_lo, i_hi]: impl's floor and
    ceil with their snap) and lattice_snap (hence |theta - theta_c| <= SNAP g), lemmas of
    their own so that each solver decides each quickly."""
    lo, hi, th, A, g = z3.Reals("lat.lo lat.hi lat.theta lat.A lat.g")
    L = lattice("lat", lo, hi, th, A, g)
    key = "lo <= theta <= hi"
    hyps = (("g > 0", g > 0), (key, z3.And(lo <= th, th <= hi))) + L.defs
    names = dict(lo=lo, hi=hi, theta=th, A=A, g=g, **L.names())
    x = (th - A) / g
    span = lemma("lattice_span", hyps, z3.And(z3.ToReal(L.i_lo) - SNAP_Q <= x,
                                              x <= z3.ToReal(L.i_hi) + SNAP_Q), key, names=names)
    with_span = hyps + tuple(span.use((), "the box's lattice"))
    snap = lemma("lattice_snap", with_span, snap_bound(th, L.theta_c, SNAP_Q * g), key,
                 names=names)
    whole = lemma("lattice", with_span + tuple(snap.use((), "the box's lattice")),
                  lattice_goal(L, th, A, g), key, names=names)
    return span, snap, whole


def margin_parts(arc: ArcChord, g: Vec, reach: Vec, G: Vec) -> tuple[z3.ArithRef, ...]:
    """The derived margin's terms: the snap slack SNAP g_q R_q per joint, then Margin.arc_chord's
    bound at R_q over the cell's turn G_q (0 for a joint with one lattice point)."""
    return ((SNAP_Q * g[0]) * reach[0], (SNAP_Q * g[1]) * reach[1], arc.delta_at(reach[0], G[0]),
            arc.delta_at(reach[1], G[1]))


def _margin_covers(arc: ArcChord, link: int, margin: Callable[..., object]) -> Lemma:
    """impl.sweep_margin covers the derived margin: the snap slack and Margin.arc_chord's bound
    over each moving joint's lattice step, at the link's reach."""
    P = f"mc{link + 1}"
    g1, g2, rb, re, dl, G1, G2 = z3.Reals(f"{P}.g1 {P}.g2 {P}.Rb {P}.Re {P}.Delta {P}.G1 {P}.G2")
    m1, m2 = z3.Bools(f"{P}.moving1 {P}.moving2")
    key = f"Delta = impl.sweep_margin(arm, link {link + 1}, g, moving), read"
    moving = (m1, m2) if link == 1 else (m1, z3.BoolVal(False))
    s1, s2, e1, e2 = margin_parts(arc, (g1, g2), (rb, re), (G1, G2))
    hyps = [("0 < g_q <= 3.14", z3.And(0 < g1, g1 <= G_MAX, 0 < g2, g2 <= G_MAX)),
            ("R_base, R_elbow >= 0", z3.And(rb >= 0, re >= 0)),
            ("G1 = g1 if joint 1 moves, else 0", G1 == z3.If(m1, g1, z3.RealVal(0)))]
    if link == 1:
        hyps.append(("G2 = g2 if joint 2 moves, else 0", G2 == z3.If(m2, g2, z3.RealVal(0))))
    hyps.append((key, dl == impl_margin(link, (g1, g2), (rb, re), moving, margin)))
    if link == 1:
        goal = z3.And(z3.And(s1 >= 0, s2 >= 0, e1 >= 0, e2 >= 0), s1 + s2 + e1 + e2 <= dl, dl >= 0)
    else:
        goal = z3.And(z3.And(s1 >= 0, e1 >= 0), s1 + e1 <= dl, dl >= 0)
    names = dict(g1=g1, g2=g2, Rb=rb, Re=re, Delta=dl, moving1=m1, G1=G1)
    if link == 1:
        names.update(moving2=m2, G2=G2)
    return lemma(f"margin_covers_link{link + 1}", hyps, goal, key, names=names)


# --- (c) region soundness: compositions, proved for every sq and dt ---------------------------

def _elbow_reach(l2: z3.ArithRef, r: z3.ArithRef, re: z3.ArithRef) -> z3.BoolRef:
    return z3.And(re >= 0, re * re == (l2 + r) * (l2 + r) + r * r)


def _chord(k: dict[str, Lemma]) -> Lemma:
    """Chord <= arc: turning by alpha - beta, |alpha - beta| <= s, moves a point at radius <= R
    about o by at most s R (from cos x >= 1 - x^2/2)."""
    al, be, R, s = z3.Reals("ch.alpha ch.beta ch.R ch.s")
    o, w = _v("ch.o"), _v("ch.w")
    x = al - be
    X, Y = _add(o, _rot(e(al), w)), _add(o, _rot(e(be), w))
    y = _sub(_rot(e(x), w), w)
    key = "-s <= alpha - beta <= s"
    hyps = [(key, snap_bound(al, be, s)), ("|w| <= R", z3.And(R >= 0, N2(w) <= R * R)),
            a3_unit(be, "beta"), a3_unit(x, "x = alpha - beta"),
            a3_cos_bound(x, "x = alpha - beta"), a3_sum(al, be, x, "alpha = beta + x")]
    hyps += k["chord_id"].at("alpha, beta", A=e(al), B=e(be), X=e(x), o=o, w=w)
    hyps += k["rot_norm"].at("e(beta), the turned difference", cs=e(be), y=y, z=_sub(X, Y))
    hyps += k["chord0"].at("x = alpha - beta", cs=e(x), x=x, R=R, s=s, w=w)
    return lemma("chord", hyps, N2(_sub(X, Y)) <= (s * R) * (s * R), key, abstract=True,
                 names=dict(alpha=al, beta=be, R=R, s=s, o=o, w=w))


def _arc_in_place(arc: ArcChord, k: dict[str, Lemma]) -> tuple[Lemma, z3.ArithRef]:
    """A point at radius r = |w| <= R from a pivot o, turning from a0 through G <= 3.14, stays
    within Margin.arc_chord's bound at R of the chord between its end positions: the lemma at
    the origin, instantiated at (r, G, e(G/2), e(psi)), moved by the rigid motion R(mid)."""
    th, a0, G, r, R, t = z3.Reals("aip.theta aip.a0 aip.G aip.r aip.R aip.t")
    o, w = _v("aip.o"), _v("aip.w")
    half = G / 2
    mid = a0 + half
    psi = th - mid
    end = a0 + G
    to_arc = ((arc.r, r), (arc.g, G), (arc.c, _COS(half)), (arc.s, _SIN(half)),
              (arc.cp, _COS(psi)), (arc.sp, _SIN(psi)))
    t_arc = z3.substitute(arc.t, *to_arc)
    mq = (z3.substitute(arc.mq[0], *to_arc), z3.substitute(arc.mq[1], *to_arc))
    ab = _ab(_COS(psi), _SIN(psi), _COS(half), _SIN(half), t)
    ab_arc = _ab(_COS(psi), _SIN(psi), _COS(half), _SIN(half), t_arc)
    X, A, B = (_add(o, _rot(e(x), w)) for x in (th, a0, end))
    diff = _sub(X, _comb(A, B, t))
    bound = arc.delta_at(R, G)
    mono = a3_cos_mono(psi, half, "psi = theta - mid, G/2")
    hyps: list[Hyp] = [
        ("t = Margin.arc_chord's chord weight at the arc", t == t_arc),
        ("0 <= G <= 3.14", z3.And(0 <= G, G <= G_MAX)),
        ("a0 <= theta <= a0 + G", z3.And(a0 <= th, th <= end)),
        ("r = |w| (a square root, named)", z3.And(r >= 0, r * r == N2(w))),
        ("|w| <= R", z3.And(R >= 0, N2(w) <= R * R)),
        a3_unit(mid, "mid = a0 + G/2"), a3_unit(psi, "psi"), a3_unit(half, "G/2"),
        a3_cos_bound(half, "G/2"), mono, a3_sin_nonneg(half, "G/2"), a3_cos_nonneg(half, "G/2"),
        a3_sum(th, mid, psi, "theta = mid + psi"), a3_diff(a0, mid, half, "a0 = mid - G/2"),
        a3_sum(end, mid, half, "a0 + G = mid + G/2"),
    ]
    hyps += arc.lemma().use(to_arc, "r, G, e(G/2), e(psi)")
    hyps += k["rigid_id"].at("the arc", M=e(mid), P=e(psi), H=e(half), T=e(th), S0=e(a0),
                             S1=e(end), t=t, o=o, w=w)
    hyps += k["rot_norm"].at("R(mid)", cs=e(mid), y=_rot(ab, w), z=diff)
    hyps += k["rot_scale"].at("the scaled rotation", cs=ab, y=w, z=_rot(ab, w))
    hyps += k["scale_norm"].at("m - q = r (..)", c=r, y=ab_arc, z=mq)
    hyps += k["arc_monotone"].at("r <= R", r=r, R=R, G=G, m=N2(diff))
    goal = z3.And(0 <= t, t <= 1, N2(diff) <= bound * bound)
    return (lemma("arc_in_place", hyps, goal, mono[0], abstract=True,
                  names=dict(theta=th, a0=a0, G=G, r=r, R=R, o=o, w=w, t=t)), t_arc)


def _reach_link2(k: dict[str, Lemma]) -> Lemma:
    be, l1, l2, r, re, u, v = z3.Reals("rl.beta rl.l1 rl.l2 rl.r rl.Re rl.u rl.v")
    key = "R_elbow = sqrt((l2 + r)^2 + r^2)"
    p = _rot(e(be), (u, v))
    hyps = [a3_unit(be, "theta2"), ("l1, l2, r > 0", z3.And(l1 > 0, l2 > 0, r > 0)),
            (key, _elbow_reach(l2, r, re)),
            ("(u, v) in link 2's rectangle", in_rect((u, v), r, l2))]
    hyps += k["reach_uv_link2"].at("link 2", ell=l2, r=r, R=re, u=u, v=v)
    hyps += k["rot_norm"].at("R(theta2)", cs=e(be), y=(u, v), z=p)
    hyps += k["reach_shift"].at("(l1, 0) + R(theta2) (u, v)", l1=l1, R=re, y=p)
    goal = z3.And(N2((u, v)) <= re * re, N2(_wvec(l1, be, u, v)) <= (l1 + re) * (l1 + re))
    return lemma("reach_link2", hyps, goal, key, abstract=True,
                 names=dict(beta=be, l1=l1, l2=l2, r=r, Re=re, u=u, v=v))


def _grow(k: dict[str, Lemma]) -> Lemma:
    """A point of a link rectangle (frame at angle phi) moved by d, |d| <= delta, lies in the
    rectangle grown by delta, at the frame coordinates grown_coords gives."""
    phi, u, v, r, ell, dl = z3.Reals("gw.phi gw.u gw.v gw.r gw.ell gw.delta")
    J, d = _v("gw.J"), _v("gw.d")
    key = "|d| <= delta"
    c, s = e(phi)
    hyps = [a3_unit(phi, "phi"), ("(u, v) in the rectangle", in_rect((u, v), r, ell)),
            ("delta >= 0", dl >= 0), (key, N2(d) <= dl * dl)]
    hyps += k["proj_id"].at("the frame at phi", cs=e(phi), d=d)
    hyps += k["proj_bound"].at("d in the frame", p=c * d[0] + s * d[1], q=-s * d[0] + c * d[1],
                               delta=dl)
    hyps += k["grow_id"].at("the frame at phi", cs=e(phi), u=u, v=v, J=J, d=d)
    uv2 = grown_coords(phi, u, v, d)
    goal = z3.And(_veq(_add(_add(J, _rot(e(phi), (u, v))), d), _add(J, _rot(e(phi), uv2))),
                  in_rect(uv2, r + dl, ell))
    return lemma("grow", hyps, goal, key, abstract=True,
                 names=dict(phi=phi, u=u, v=v, r=r, ell=ell, delta=dl, J=J, d=d))


def _weighted(ws: Sequence[z3.ArithRef], pts: Sequence[Vec]) -> Vec:
    return (z3.Sum([w * p[0] for w, p in zip(ws, pts)]),
            z3.Sum([w * p[1] for w, p in zip(ws, pts)]))


def _triangle(k: dict[str, Lemma]) -> Lemma:
    """|x| <= a, |y| <= b (a, b >= 0) and z = x + y give |z| <= a + b, from expand and
    dot_bound (combine2_norm's step, a lemma so that each solver decides it alone)."""
    x, y, z = _v("tri.x"), _v("tri.y"), _v("tri.z")
    a, b = z3.Reals("tri.a tri.b")
    key = "|y| <= b"
    hyps: list[Hyp] = [("z = x + y", _veq(z, _add(x, y))), ("a, b >= 0", z3.And(a >= 0, b >= 0)),
                       ("|x| <= a", N2(x) <= a * a), (key, N2(y) <= b * b)]
    hyps += k["expand"].at("z = x + y", x=x, y=y, z=z)
    hyps += k["dot_bound"].at("x, y", x=x, y=y, a=a, b=b)
    return lemma("triangle", hyps, N2(z) <= (a + b) * (a + b), key, abstract=True,
                 names=dict(x=x, y=y, z=z, a=a, b=b))


def _scale_bound(k: dict[str, Lemma]) -> Lemma:
    """z = c y with c >= 0 and |y| <= b (b >= 0) give |z| <= c b, from scale_norm."""
    y, z = _v("sb.y"), _v("sb.z")
    c, b = z3.Reals("sb.c sb.b")
    key = "|y| <= b"
    hyps: list[Hyp] = [("z = c y", _veq(z, _scale(c, y))), ("c, b >= 0", z3.And(c >= 0, b >= 0)),
                       (key, N2(y) <= b * b)]
    hyps += k["scale_norm"].at("z = c y", c=c, y=y, z=z)
    return lemma("scale_bound", hyps, N2(z) <= (c * b) * (c * b), key, abstract=True,
                 names=dict(y=y, z=z, c=c, b=b))


@dataclass(frozen=True)
class _Combine2:
    """The names of the two joints' combination (link 2): X0 (the point), X1, X2 (after
    snapping theta1, theta2), A, B (its chord's ends about the base), A', B' (their chord points
    about the elbow, between the corners K), h = (1 - lam) A' + lam B', D = X0 - h. What it
    concludes is split in two lemmas that each solver decides alone: the bound on |D|
    (combine2_norm) and the corners' weights (combine2_weights)."""

    X0: Vec
    X1: Vec
    X2: Vec
    A: Vec
    B: Vec
    K: tuple[Vec, Vec, Vec, Vec]
    lam: z3.ArithRef
    mu: z3.ArithRef
    nu: z3.ArithRef
    s1: z3.ArithRef
    s2: z3.ArithRef
    e1: z3.ArithRef
    e2: z3.ArithRef
    dl: z3.ArithRef
    D: Vec

    @classmethod
    def named(cls) -> _Combine2:
        X0, X1, X2, A, B, K00, K01, K10, K11 = (_v(f"cb2.{n}") for n in
                                                ["X0", "X1", "X2", "A", "B", "K00", "K01", "K10", "K11"])
        lam, mu, nu, s1, s2, e1, e2, dl = z3.Reals("cb2.lam cb2.mu cb2.nu cb2.s1 cb2.s2 cb2.e1 "
                                                   "cb2.e2 cb2.Delta")
        return cls(X0, X1, X2, A, B, (K00, K01, K10, K11), lam, mu, nu, s1, s2, e1, e2, dl,
                   _v("cb2.D"))

    @property
    def corners(self) -> tuple[Vec, Vec]:
        """A', B': the chord's ends' chord points about the elbow, between the corners."""
        K = self.K
        return _comb(K[0], K[1], self.mu), _comb(K[2], K[3], self.nu)

    @property
    def h(self) -> Vec:
        A2, B2 = self.corners
        return _comb(A2, B2, self.lam)

    @property
    def weights(self) -> tuple[z3.ArithRef, ...]:
        lam, mu, nu = self.lam, self.mu, self.nu
        return ((1 - lam) * (1 - mu), (1 - lam) * mu, lam * (1 - nu), lam * nu)

    def hyps(self) -> list[Hyp]:
        """The premises both halves share (those link2_in_region instantiates)."""
        A2, B2 = self.corners
        X0, X1, X2, s1, s2, e1, e2 = self.X0, self.X1, self.X2, self.s1, self.s2, self.e1, self.e2
        lam, mu, nu = self.lam, self.mu, self.nu
        h1 = _comb(self.A, self.B, lam)
        return [
            ("D = X0 - h", _veq(self.D, _sub(X0, self.h))),
            ("|X0 - X1| <= s1", N2(_sub(X0, X1)) <= s1 * s1),
            ("|X1 - X2| <= s2", N2(_sub(X1, X2)) <= s2 * s2),
            ("|X2 - h1| <= e1", N2(_sub(X2, h1)) <= e1 * e1),
            ("|A - A'| <= e2", N2(_sub(self.A, A2)) <= e2 * e2),
            ("|B - B'| <= e2", N2(_sub(self.B, B2)) <= e2 * e2),
            ("s1, s2, e1, e2 >= 0", z3.And(s1 >= 0, s2 >= 0, e1 >= 0, e2 >= 0)),
            ("s1 + s2 + e1 + e2 <= Delta", s1 + s2 + e1 + e2 <= self.dl),
            ("0 <= lam, mu, nu <= 1", z3.And(0 <= lam, lam <= 1, 0 <= mu, mu <= 1, 0 <= nu,
                                             nu <= 1)),
        ]

    def names(self) -> dict[str, object]:
        K = self.K
        return dict(X0=self.X0, X1=self.X1, X2=self.X2, A=self.A, B=self.B, K00=K[0], K01=K[1],
                    K10=K[2], K11=K[3], lam=self.lam, mu=self.mu, nu=self.nu, s1=self.s1,
                    s2=self.s2, e1=self.e1, e2=self.e2, Delta=self.dl, D=self.D)


def _combine2_norm(k: dict[str, Lemma], c: _Combine2) -> Lemma:
    """The two joints' bounds add: |D| <= s1 + s2 + e1 + e2 <= Delta, by four triangle steps
    (X0 - X2, X0 - h1, h1 - h, X0 - h) and the scaled bounds of A - A', B - B'."""
    A2, B2 = c.corners
    h1 = _comb(c.A, c.B, c.lam)
    dA, dB = _sub(c.A, A2), _sub(c.B, B2)
    xa, yb = _scale(1 - c.lam, dA), _scale(c.lam, dB)
    c4 = _add(xa, yb)
    z1, z2 = _sub(c.X0, c.X2), _sub(c.X0, h1)
    s12 = c.s1 + c.s2
    hyps = c.hyps()
    hyps += k["triangle"].at("X0 - X2", x=_sub(c.X0, c.X1), y=_sub(c.X1, c.X2), z=z1, a=c.s1,
                             b=c.s2)
    hyps += k["triangle"].at("X0 - h1", x=z1, y=_sub(c.X2, h1), z=z2, a=s12, b=c.e1)
    hyps += k["scale_bound"].at("(1 - lam)(A - A')", c=1 - c.lam, y=dA, z=xa, b=c.e2)
    hyps += k["scale_bound"].at("lam (B - B')", c=c.lam, y=dB, z=yb, b=c.e2)
    hyps += k["triangle"].at("h1 - h", x=xa, y=yb, z=c4, a=(1 - c.lam) * c.e2, b=c.lam * c.e2)
    hyps += k["triangle"].at("X0 - h", x=z2, y=c4, z=c.D, a=s12 + c.e1,
                             b=(1 - c.lam) * c.e2 + c.lam * c.e2)
    hyps += k["square_monotone"].at("s1 + s2 + e1 + e2 <= Delta", a=s12 + c.e1 + c.e2, b=c.dl,
                                    m=N2(c.D))
    return lemma("combine2_norm", hyps, N2(c.D) <= c.dl * c.dl, "s1 + s2 + e1 + e2 <= Delta",
                 abstract=True, names=c.names())


def _combine2_weights(c: _Combine2) -> Lemma:
    """The corners' weights: with D = X0 - h, the corners' weights are >= 0, sum to 1 and
    X0 = sum of w_c (K_c + D) (a polynomial identity, no norms)."""
    ws = c.weights
    hyps = [h for h in c.hyps() if h[0] in ("D = X0 - h", "0 <= lam, mu, nu <= 1")]
    goal = z3.And(*[w >= 0 for w in ws], z3.Sum(ws) == 1,
                  _veq(c.X0, _weighted(ws, [_add(K, c.D) for K in c.K])))
    return lemma("combine2_weights", hyps, goal, "D = X0 - h", abstract=True, names=c.names())


def _combine1(k: dict[str, Lemma]) -> Lemma:
    """One joint: |X0 - h1| <= s1 + e1 <= Delta, h1 = (1 - lam) A + lam B, and
    X0 = (1 - lam)(A + (X0 - h1)) + lam (B + (X0 - h1))."""
    X0, X1, A, B = (_v(f"cb1.{n}") for n in ("X0", "X1", "A", "B"))
    lam, s1, e1, dl = z3.Reals("cb1.lam cb1.s1 cb1.e1 cb1.Delta")
    h1 = _comb(A, B, lam)
    D = _v("cb1.D")
    key = "s1 + e1 <= Delta"
    hyps: list[Hyp] = [
        ("D = X0 - h1", _veq(D, _sub(X0, h1))),
        ("|X0 - X1| <= s1", N2(_sub(X0, X1)) <= s1 * s1),
        ("|X1 - h1| <= e1", N2(_sub(X1, h1)) <= e1 * e1),
        ("s1, e1 >= 0", z3.And(s1 >= 0, e1 >= 0)), (key, s1 + e1 <= dl),
        ("0 <= lam <= 1", z3.And(0 <= lam, lam <= 1)),
    ]
    hyps += k["expand"].at("X0 - h1", x=_sub(X0, X1), y=_sub(X1, h1), z=D)
    hyps += k["dot_bound"].at("X0 - X1, X1 - h1", x=_sub(X0, X1), y=_sub(X1, h1), a=s1, b=e1)
    hyps += k["square_monotone"].at("s1 + e1 <= Delta", a=s1 + e1, b=dl, m=N2(D))
    ws = (1 - lam, lam)
    goal = z3.And(N2(D) <= dl * dl, *[w >= 0 for w in ws],
                  _veq(X0, _weighted(ws, [_add(A, D), _add(B, D)])))
    return lemma("combine1", hyps, goal, key, abstract=True,
                 names=dict(X0=X0, X1=X1, A=A, B=B, lam=lam, s1=s1, e1=e1, Delta=dl, D=D))


def _transport() -> Lemma:
    """A norm bound on X - Y holds for equal points X', Y' (congruence, for every sq)."""
    X, Y, X2, Y2 = (_v(f"tp.{n}") for n in ("X", "Y", "X'", "Y'"))
    m = z3.Real("tp.m")
    key = "X = X'"
    hyps = ((key, _veq(X, X2)), ("Y = Y'", _veq(Y, Y2)), ("|X - Y|^2 <= m", N2(_sub(X, Y)) <= m))
    return lemma("transport", hyps, N2(_sub(X2, Y2)) <= m, key, abstract=True,
                 names=dict(X=X, Y=Y, X2=X2, Y2=Y2, m=m))


def _transport_chord() -> Lemma:
    """A norm bound on X minus a chord point of A B holds for equal points X', A', B'."""
    X, A, B, X2, A2, B2 = (_v(f"tc.{n}") for n in ("X", "A", "B", "X'", "A'", "B'"))
    t, m = z3.Reals("tc.t tc.m")
    key = "X = X'"
    hyps = ((key, _veq(X, X2)), ("A = A'", _veq(A, A2)), ("B = B'", _veq(B, B2)),
            ("|X - ((1 - t) A + t B)|^2 <= m", N2(_sub(X, _comb(A, B, t))) <= m))
    return lemma("transport_chord", hyps, N2(_sub(X2, _comb(A2, B2, t))) <= m, key,
                 abstract=True, names=dict(X=X, A=A, B=B, X2=X2, A2=A2, B2=B2, t=t, m=m))


def _shift_eq() -> Lemma:
    """A point K named by its definition M, moved by d to Q (M + d = Q), gives K + d = Q: the
    step from grow's conclusion at a corner to sum_subst's premise, made explicit."""
    K, M, d, Q = (_v(f"se.{n}") for n in ("K", "M", "d", "Q"))
    key = "K = M"
    hyps = ((key, _veq(K, M)), ("M + d = Q", _veq(_add(M, d), Q)))
    return lemma("shift_eq", hyps, _veq(_add(K, d), Q), key, names=dict(K=K, M=M, d=d, Q=Q))


def _sum_subst(n: int) -> Lemma:
    """X = sum of w_i P_i and P_i = Q_i give X = sum of w_i Q_i."""
    X = _v(f"ss{n}.X")
    Ps = [_v(f"ss{n}.P{i}") for i in range(n)]
    Qs = [_v(f"ss{n}.Q{i}") for i in range(n)]
    ws = list(z3.Reals(" ".join(f"ss{n}.w{i}" for i in range(n))))
    key = "P_0 = Q_0"
    hyps = [("X = sum w_i P_i", _veq(X, _weighted(ws, Ps)))]
    hyps += [(f"P_{i} = Q_{i}", _veq(P, Q)) for i, (P, Q) in enumerate(zip(Ps, Qs))]
    names: dict[str, object] = dict(X=X)
    for i in range(n):
        names.update({f"P{i}": Ps[i], f"Q{i}": Qs[i], f"w{i}": ws[i]})
    return lemma(f"sum_subst{n}", hyps, _veq(X, _weighted(ws, Qs)), key, abstract=True,
                 names=names)


@dataclass(frozen=True)
class Kit:
    """Every lemma of Safety.region_soundness by name; what the tests mutate: Margin.arc_chord's
    VC and the margin function read as impl's."""

    arc: ArcChord
    lemmas: dict[str, Lemma]
    arc_t: z3.ArithRef           # Margin.arc_chord's chord weight, in arc_in_place's names
    margin: Callable[..., object]

    def __getitem__(self, name: str) -> Lemma:
        return self.lemmas[name]


def _pins(pairs: Sequence[tuple[z3.ExprRef, int | z3.ArithRef]]
          ) -> list[tuple[z3.ExprRef, z3.ExprRef]]:
    return [(c, z3.RealVal(x) if isinstance(x, int) else x) for c, x in pairs]


@dataclass(frozen=True)
class _Chain:
    """What _snapped_to_corners adds, and the terms the caller's goal reads."""

    hyps: list[Hyp]
    ws: tuple[z3.ArithRef, ...]
    Qs: list[Vec]
    D: Vec


def _snapped_to_corners(kit: Kit, k: dict[str, Lemma], tag: str,
                        frame: tuple[Vec, z3.ArithRef, z3.ArithRef, z3.ArithRef],
                        theta: tuple[z3.ArithRef, ...], lats: tuple[Any, Any],
                        radii: tuple[z3.ArithRef, ...], named: tuple[Any, ...],
                        alphas: tuple[z3.ArithRef, ...], phis: tuple[z3.ArithRef, ...],
                        points: str, grown: str,
                        grow: Callable[[int, z3.ArithRef, z3.ArithRef, Vec], list[Hyp]]
                        ) -> _Chain:
    """The lemma instances that carry a point (u, v) rigidly fixed to link 2 from the box's
    configuration to the hull of the lattice cell's corners (docs/model.md §2, §10 (c)):
    snapping theta1 and theta2 (chord, transport), the three arcs (arc_in_place,
    transport_chord), the two joints' bounds added (combine2_norm, combine2_weights), each
    corner's part grown (``grow``: the rectangle's or the tool's square), the corners' points
    shifted (shift_eq) and summed (sum_subst4). One chain for link 2 (link2_in_region) and the
    tool (grown_in_region); ``tag`` prefixes its Z3 names, ``points`` and ``grown`` name its
    instances."""
    b, l1, u, v = frame
    th1, th2, g1, g2 = theta
    L1, L2 = lats
    rb, re, r1, r2, dl = radii
    X0, X1, X2, A, B, Ks = named
    t1c, t2c = L1.theta_c, L2.theta_c
    c1, G1, c2, G2 = L1.c, L1.G, L2.c, L2.G
    c1e = c1 + G1

    def P(alpha: z3.ArithRef, phi: z3.ArithRef) -> Vec:
        return _point2(b, l1, alpha, phi, u, v)
    hyps: list[Hyp] = []
    for alpha, beta, where in ((th1, th2, "theta"), (t1c, th2, "(theta1', theta2)"),
                               (t1c, t2c, "theta'"), (c1, t2c, "(c1, theta2')"),
                               (c1e, t2c, "(c1 + G1, theta2')")):
        hyps.append(a3_sum(alpha + beta, alpha, beta, where))
        hyps += k["kin"].at(where, A=e(alpha), B=e(beta), AB=e(alpha + beta), l1=l1, u=u, v=v,
                            b=b)
    hyps += k["chord"].at("snapping theta1", alpha=th1, beta=t1c, o=b, w=_wvec(l1, th2, u, v),
                          R=rb, s=SNAP_Q * g1)

    def nested(alpha: z3.ArithRef, beta: z3.ArithRef) -> Vec:
        return _add(b, _rot(e(alpha), _wvec(l1, beta, u, v)))
    s1, s2, e1, e2 = margin_parts(kit.arc, (g1, g2), (rb, re), (G1, G2))
    hyps += k["transport"].at("snapping theta1, in docs/model.md §2's form", X=nested(th1, th2),
                              Y=nested(t1c, th2), X2=X0, Y2=X1, m=s1 * s1)
    hyps += k["chord"].at("snapping theta2", alpha=t1c + th2, beta=t1c + t2c,
                          o=_elbow(b, l1, t1c), w=(u, v), R=re, s=SNAP_Q * g2)
    aip = k["arc_in_place"]
    arcs = (("the base arc", dict(theta=t1c, a0=c1, G=G1, o=b, w=_wvec(l1, t2c, u, v), r=r1,
                                  R=rb)),
            ("the elbow arc at c1", dict(theta=c1 + t2c, a0=c1 + c2, G=G2, o=_elbow(b, l1, c1),
                                         w=(u, v), r=r2, R=re)),
            ("the elbow arc at c1 + G1", dict(theta=c1e + t2c, a0=c1e + c2, G=G2,
                                              o=_elbow(b, l1, c1e), w=(u, v), r=r2, R=re)))
    lam, mu, nu = z3.Reals(f"{tag}.lam {tag}.mu {tag}.nu")
    for t, (where, arc_at) in zip((lam, mu, nu), arcs):
        hyps.append((f"{t} = Margin.arc_chord's chord weight on {where}",
                     t == aip.term(kit.arc_t, **arc_at)))
        hyps += aip.at(where, t=t, **arc_at)
    hyps += k["transport_chord"].at("the base arc, in docs/model.md §2's form",
                                    X=nested(t1c, t2c), A=nested(c1, t2c), B=nested(c1e, t2c),
                                    X2=X2, A2=A, B2=B, t=lam, m=e1 * e1)
    for where, X2_, A2_, B2_, alpha, t in (("the elbow arc at c1", A, Ks[0], Ks[1], c1, mu),
                                           ("the elbow arc at c1 + G1", B, Ks[2], Ks[3], c1e,
                                            nu)):
        # The elbow arcs' points, named (A, B and the corners): what combine2_norm reads.
        hyps += k["transport_chord"].at(f"{where}, in docs/model.md §2's form",
                                        X=P(alpha, alpha + t2c), A=P(alpha, alpha + c2),
                                        B=P(alpha, (alpha + c2) + G2), X2=X2_, A2=A2_, B2=B2_,
                                        t=t, m=e2 * e2)
    D = _v(f"{tag}.D")
    hyps.append(("D = X0 - h, h = (1 - lam) A' + lam B' (named)",
                 _veq(D, _sub(X0, _comb(_comb(Ks[0], Ks[1], mu), _comb(Ks[2], Ks[3], nu), lam)))))
    # The two joints' bounds add (combine2_norm) and the corners' weights (combine2_weights).
    cb2 = dict(X0=X0, X1=X1, X2=X2, A=A, B=B, K00=Ks[0], K01=Ks[1], K10=Ks[2], K11=Ks[3],
               lam=lam, mu=mu, nu=nu, s1=s1, s2=s2, e1=e1, e2=e2, Delta=dl, D=D)
    hyps += k["combine2_norm"].at(points, **cb2)
    hyps += k["combine2_weights"].at(points, **cb2)
    for i, (alpha, phi) in enumerate(zip(alphas, phis)):
        hyps += grow(i, alpha, phi, D)
    ws = ((1 - lam) * (1 - mu), (1 - lam) * mu, lam * (1 - nu), lam * nu)
    Qs = [_add(_elbow(b, l1, a), _rot(e(ph), grown_coords(ph, u, v, D)))
          for a, ph in zip(alphas, phis)]
    for i, (alpha, phi) in enumerate(zip(alphas, phis)):
        hyps += k["shift_eq"].at(f"corner {i}", K=Ks[i], M=P(alpha, phi), d=D, Q=Qs[i])
    sub: dict[str, object] = dict(X=X0)
    for i in range(4):
        sub.update({f"P{i}": _add(Ks[i], D), f"Q{i}": Qs[i], f"w{i}": ws[i]})
    hyps += k["sum_subst4"].at(grown, **sub)
    return _Chain(hyps, ws, Qs, D)


def _link2(kit: Kit) -> Lemma:
    """Link 2 at any configuration of a box lies in the region built for it."""
    k = kit.lemmas
    b = _v("lk2.b")
    l1, l2, r, re, u, v, r1, r2, dl = z3.Reals("lk2.l1 lk2.l2 lk2.r lk2.Re lk2.u lk2.v lk2.r1 "
                                               "lk2.r2 lk2.Delta")
    rb = l1 + re
    box = box_points("lk2")
    (lo1, hi1, th1, A1, g1), (lo2, hi2, th2, A2, g2) = box.joint1, box.joint2
    L1, L2, alphas, phis, at, pts = box.L1, box.L2, box.alphas, box.phis, box.at, box.pts
    t2c, c1, G1, c2, G2 = L2.theta_c, L1.c, L1.G, L2.c, L2.G
    c1e = c1 + G1
    X0, X1, X2, A, B = box.named
    Ks = box.corners

    def P(alpha: z3.ArithRef, phi: z3.ArithRef) -> Vec:
        return _point2(b, l1, alpha, phi, u, v)
    key = "Delta = impl.sweep_margin(arm, link 2, g, moving), read"
    moving = (L1.moving, L2.moving)
    hyps: list[Hyp] = [
        ("link 2 (docs/model.md §2): l1, l2 > 0, r = w/2 > 0", z3.And(l1 > 0, l2 > 0, r > 0)),
        ("R_elbow = sqrt((l2 + r)^2 + r^2), R_base = l1 + R_elbow", _elbow_reach(l2, r, re)),
        ("theta in the box", z3.And(lo1 <= th1, th1 <= hi1, lo2 <= th2, th2 <= hi2)),
        ("lattice spacings 0 < g_q <= 3.14", z3.And(0 < g1, g1 <= G_MAX, 0 < g2, g2 <= G_MAX)),
        ("(u, v) a point of link 2's rectangle", in_rect((u, v), r, l2)),
        ("r1 = |w(theta2')|, r2 = |(u, v)| (square roots, named)",
         z3.And(r1 >= 0, r1 * r1 == N2(_wvec(l1, t2c, u, v)), r2 >= 0, r2 * r2 == N2((u, v)))),
        (key, dl == impl_margin(1, (g1, g2), (rb, re), moving, kit.margin)),
    ]
    hyps += [(f"{n} = the point (u, v) of link 2 at {where} (named)", _veq(pts[n], P(a, ph)))
             for n, a, ph, where in at]
    hyps += box.lattice_hyps(k)
    hyps += k["margin_covers_link2"].at("the box's lattice", g1=g1, g2=g2, Rb=rb, Re=re, Delta=dl,
                                        moving1=L1.moving, moving2=L2.moving, G1=G1, G2=G2)
    for beta, where in ((th2, "theta2"), (t2c, "theta2'")):
        hyps += k["reach_link2"].at(where, beta=beta, l1=l1, l2=l2, r=r, Re=re, u=u, v=v)
    chain = _snapped_to_corners(
        kit, k, "lk2", (b, l1, u, v), (th1, th2, g1, g2), (L1, L2), (rb, re, r1, r2, dl),
        (X0, X1, X2, A, B, Ks), alphas, phis, "the link's points", "the corners' grown rectangles",
        lambda i, alpha, phi, D: k["grow"].at(f"corner {i}", phi=phi, u=u, v=v, r=r, ell=l2,
                                              delta=dl, J=_elbow(b, l1, alpha), d=D))
    hyps += chain.hyps
    ws, Qs, D = chain.ws, chain.Qs, chain.D
    goal = z3.And(
        L1.i_lo <= L1.j, L1.j + L1.step <= L1.i_hi, L2.i_lo <= L2.j, L2.j + L2.step <= L2.i_hi,
        c1e == A1 + z3.ToReal(L1.j + L1.step) * g1, c2 + G2 == A2 + z3.ToReal(L2.j + L2.step) * g2,
        *[w >= 0 for w in ws], z3.Sum(ws) == 1,
        *[in_rect(grown_coords(ph, u, v, D), r + dl, l2) for ph in phis],
        _veq(X0, _weighted(ws, Qs)))
    # A small arm at rest in a one-point box (l2 + r = 2/5, r = 3/10: R_elbow = 1/2), for the
    # vacuity check; with a negative margin for the negative test's counter-model.
    q = z3.Q
    wit = _pins([(b[0], 0), (b[1], 0), (l1, q(1, 10)), (l2, q(1, 10)), (r, q(3, 10)),
                 (re, q(1, 2)), (lo1, 0), (hi1, 0), (th1, 0), (A1, 0), (g1, q(1, 2)), (lo2, 0),
                 (hi2, 0), (th2, 0), (A2, 0), (g2, q(1, 2)), (u, 0), (v, 0), (r1, q(1, 10)),
                 (r2, 0)])
    return lemma("link2_in_region", hyps, goal, key, abstract=True, witness=wit,
                 counter_witness=wit + [(dl, z3.RealVal(-1))])


def _link1(kit: Kit) -> Lemma:
    """Link 1 at any configuration of a box lies in the region built for it (it does not
    depend on theta2: its lattice has the single point anchor2 in theta2)."""
    k = kit.lemmas
    b = _v("lk1.b")
    l1, r, rb, u, v, r1, dl, g2 = z3.Reals("lk1.l1 lk1.r lk1.Rb lk1.u lk1.v lk1.r1 lk1.Delta "
                                           "lk1.g2")
    lo1, hi1, th1, A1, g1 = z3.Reals("lk1.lo1 lk1.hi1 lk1.theta1 lk1.A1 lk1.g1")
    L1 = lattice("lk1.joint1", lo1, hi1, th1, A1, g1)
    t1c, c1, G1 = L1.theta_c, L1.c, L1.G
    c1e = c1 + G1

    def P(alpha: z3.ArithRef) -> Vec:
        return _add(b, _rot(e(alpha), (u, v)))
    X0, X1, A, B = P(th1), P(t1c), P(c1), P(c1e)
    key = "Delta = impl.sweep_margin(arm, link 1, g, moving), read"
    zero = z3.RealVal(0)
    hyps: list[Hyp] = [
        ("link 1 (docs/model.md §2): l1 > 0, r = w/2 > 0", z3.And(l1 > 0, r > 0)),
        ("R_base = sqrt((l1 + r)^2 + r^2)",
         z3.And(rb >= 0, rb * rb == (l1 + r) * (l1 + r) + r * r)),
        ("theta1 in the box", z3.And(lo1 <= th1, th1 <= hi1)),
        ("lattice spacings 0 < g_q <= 3.14", z3.And(0 < g1, g1 <= G_MAX, 0 < g2, g2 <= G_MAX)),
        ("(u, v) a point of link 1's rectangle", in_rect((u, v), r, l1)),
        ("r1 = |(u, v)| (a square root, named)", z3.And(r1 >= 0, r1 * r1 == N2((u, v)))),
        (key, dl == impl_margin(0, (g1, g2), (rb, zero), (L1.moving, z3.BoolVal(False)),
                                kit.margin)),
    ]
    hyps += L1.defs
    hyps += k["lattice"].at("joint 1", lo=lo1, hi=hi1, theta=th1, A=A1, g=g1, **L1.names())
    hyps += k["margin_covers_link1"].at("the box's lattice", g1=g1, g2=g2, Rb=rb, Re=zero,
                                        Delta=dl, moving1=L1.moving, G1=G1)
    hyps += k["reach_uv_link1"].at("link 1", ell=l1, r=r, R=rb, u=u, v=v)
    hyps += k["chord"].at("snapping theta1", alpha=th1, beta=t1c, o=b, w=(u, v), R=rb,
                          s=SNAP_Q * g1)
    arc_at = dict(theta=t1c, a0=c1, G=G1, o=b, w=(u, v), r=r1, R=rb)
    lam = z3.Real("lk1.lam")
    hyps.append(("lam = Margin.arc_chord's chord weight on the base arc",
                 lam == k["arc_in_place"].term(kit.arc_t, **arc_at)))
    hyps += k["arc_in_place"].at("the base arc", t=lam, **arc_at)
    s1, _, e1, _ = margin_parts(kit.arc, (g1, g2), (rb, zero), (G1, zero))
    D = _v("lk1.D")
    hyps.append(("D = X0 - h1, h1 = (1 - lam) A + lam B (named)",
                 _veq(D, _sub(X0, _comb(A, B, lam)))))
    hyps += k["combine1"].at("the link's points", X0=X0, X1=X1, A=A, B=B, lam=lam, s1=s1, e1=e1,
                             Delta=dl, D=D)
    for i, alpha in enumerate((c1, c1e)):
        hyps += k["grow"].at(f"corner {i}", phi=alpha, u=u, v=v, r=r, ell=l1, delta=dl, J=b, d=D)
    ws = (1 - lam, lam)
    Qs = [_add(b, _rot(e(a), grown_coords(a, u, v, D))) for a in (c1, c1e)]
    hyps += k["sum_subst2"].at("the corners' grown rectangles", X=X0, P0=_add(A, D),
                               P1=_add(B, D), Q0=Qs[0], Q1=Qs[1], w0=ws[0], w1=ws[1])
    goal = z3.And(L1.i_lo <= L1.j, L1.j + L1.step <= L1.i_hi,
                  c1e == A1 + z3.ToReal(L1.j + L1.step) * g1, *[w >= 0 for w in ws],
                  *[in_rect(grown_coords(a, u, v, D), r + dl, l1) for a in (c1, c1e)],
                  _veq(X0, _weighted(ws, Qs)))
    # A small arm at rest in a one-point box (l1 + r = 2/5, r = 3/10: R_base = 1/2), for the
    # vacuity check; with a negative margin for the negative test's counter-model.
    q = z3.Q
    wit = _pins([(b[0], 0), (b[1], 0), (l1, q(1, 10)), (r, q(3, 10)), (rb, q(1, 2)), (lo1, 0),
                 (hi1, 0), (th1, 0), (A1, 0), (g1, q(1, 2)), (g2, q(1, 2)), (u, 0), (v, 0),
                 (r1, 0)])
    return lemma("link1_in_region", hyps, goal, key, abstract=True, witness=wit,
                 counter_witness=wit + [(dl, z3.RealVal(-1))])


def region_kit(arc_vc: VC | None = None, margin: Callable[..., object] = sweep_margin) -> Kit:
    """Every lemma of Safety.region_soundness; ``arc_vc`` and ``margin`` replace
    Margin.arc_chord's VC and impl.sweep_margin (the tests' mutants)."""
    arc = arc_chord(arc_vc)
    k: dict[str, Lemma] = {}
    for L in (_rot_norm(), _rot_scale(), _scale_norm(), _expand(), _dot_bound(),
              _square_monotone(), _proj_id(), _proj_bound(), _grow_id(), _chord0(), _chord_id(),
              _rigid_id(), _arc_monotone(arc), _kin(), _reach_uv(0), _reach_uv(1), _reach_shift(),
              *_lattice(), _margin_covers(arc, 0, margin), _margin_covers(arc, 1, margin)):
        k[L.vc.name] = L
    k.update(arc_steps(arc, k))
    k["arc_in_place"], arc_t = _arc_in_place(arc, k)
    c2 = _Combine2.named()
    for L in (_triangle(k), _scale_bound(k)):
        k[L.vc.name] = L
    for L in (_combine2_norm(k, c2), _combine2_weights(c2)):
        k[L.vc.name] = L
    for L in (_chord(k), _reach_link2(k), _grow(k), _combine1(k), _transport(),
              _transport_chord(), _shift_eq(), _sum_subst(2), _sum_subst(4)):
        k[L.vc.name] = L
    kit = Kit(arc, k, arc_t, margin)
    k["link1_in_region"] = _link1(kit)
    k["link2_in_region"] = _link2(kit)
    return kit


def region_query(kit: Kit | None = None) -> Z3Query:
    """Safety.region_soundness: Margin.arc_chord's VC (re-proved from its premises through
    arc_weight, arc_dist and arc_gap: the lemma the margin rests on) and every lemma of the
    kit."""
    kit = kit or region_kit()
    check_lattice_reading()
    first = kit["Margin.arc_chord"].vc
    return Z3Query((first,) + tuple(L.vc for L in kit.lemmas.values() if L.vc is not first))
