"""The end-to-end safety theorem (docs/model.md §10): the ``Safety.*`` obligations.

For each variant, a path valid under the fixed is_path over a D_R that meets Theorem 1/3's
postcondition never lets the arms touch, at any instant t >= 0 of the executed motion (the
principal's PTP motion, the subordinate linear in joint space from cell to cell, one cell per
dt, then at rest). The parts, each an obligation:

(a) ``Safety.<variant>.principal_in_layer_box``: theta_L(t) = start + (goal - start)
    min(t / Tf, 1) lies in layer k's box (the variant's rule) for t in [k dt, (k+1) dt], and
    in the rest layer's box for t >= N dt (N = max(1, ceil(Tf / dt))).
(b) ``Safety.subordinate_in_cell_box``: the linear move from cell L_k to a neighbour stays in
    L_k's box over the whole step; on a valid path every step is such a move, a wait once the
    list has ended.
(c) ``Safety.region_soundness``: a point of a link at any configuration of a box lies in the
    region built for that box (the lattice of impl.lattice_range's formula, the link
    rectangles grown by impl.sweep_margin, their convex hull), the margin derived from
    Margin.arc_chord and the snap slack, and compared with the margin sweep_margin computes.
(d) ``Safety.separation``: a pair BuiltDR frees (float distance > eps) is at an exact distance
    > 0 when the float value is within spec.DISTANCE_ERROR_M of the exact one (ledger A12) and
    that bound is below eps; regions at a positive distance hold links that share no point.
(e) ``Safety.<variant>.composition``: (a)-(d), the fixed is_path and the time-layer
    decomposition give the theorem; each premise that is not a lemma's instance is shown
    needed by cfmpa prove's negative controls (proofs/_controls.py).

Trigonometry. sin and cos are the uninterpreted functions ``Sin``, ``Cos`` over Z3's reals;
all that is known of them are the ledger's facts (A3), each stated at points the proof names.
A lemma is a VC over free names; a proof that uses it instantiates it by substitution, like the
step lemmas of Lemma.sweep_margin: its premises are then Z3's to discharge, and the facts it
rests on (A3 instances and instances of other proved lemmas, true at any point) are carried into
the proof's hypotheses, substituted. Where a proof only chains norm bounds, |v|^2 is the
uninterpreted ``sq`` and the dot product ``dt``: such a VC is valid for every sq and dt, hence
for the polynomials, under which its lemma instances are the proved lemmas' instances.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import z3

from ..impl import SNAP, lattice_range, link_reach, sweep_margin
from ..spec import (
    DISTANCE_ERROR_M,
    EPS,
    MAX_SPACING,
    Arm,
    Variant,
    cell_box,
    ptp_angles,
    ptp_fraction,
)
from ..spec.z3defs import (
    REGION,
    Z3Dims,
    abs_int,
    adjacent,
    blocked_exact,
    in_grid,
    is_path_fixed,
    member,
    position,
    z3_path,
)
from ._obl_margin import margin_obligations
from ._obligation import VC, Method, Obligation, Verdict, Z3Query

__all__ = ["VARIANTS", "safety_obligations"]

GROUP = "End-to-end safety (docs/model.md §10)"

VARIANTS = ("original", "modified", "tight")

#: A rational below pi (the lattice spacings' bound, as in Margin.arc_chord).
G_MAX = z3.Q(MAX_SPACING.numerator, MAX_SPACING.denominator)
#: impl.SNAP and spec.EPS as the rationals their decimal literals denote.
SNAP_Q = z3.RealVal(repr(SNAP))
EPS_Q = z3.RealVal(repr(EPS))

Vec = tuple[z3.ArithRef, z3.ArithRef]
Hyp = tuple[str, z3.BoolRef]
_R = z3.RealSort()

# --- vectors, norms, trigonometry -----------------------------------------------------------

_SQ = z3.Function("sq", _R, _R, _R)
_DT = z3.Function("dt", _R, _R, _R, _R, _R)
_V0, _V1, _V2, _V3 = (z3.Var(i, _R) for i in range(4))
#: sq(a, b) := a^2 + b^2 and dt(a, b, c, d) := a c + b d: what the abstract norms stand for.
_CONCRETE = ((_SQ, _V0 * _V0 + _V1 * _V1), (_DT, _V0 * _V2 + _V1 * _V3))


def concrete(f: z3.ExprRef) -> z3.ExprRef:
    """f with sq and dt replaced by the polynomials they stand for."""
    return z3.substitute_funs(f, *_CONCRETE)


def _v(name: str) -> Vec:
    return z3.Real(f"{name}.x"), z3.Real(f"{name}.y")


def _add(a: Vec, b: Vec) -> Vec:
    return (a[0] + b[0], a[1] + b[1])


def _sub(a: Vec, b: Vec) -> Vec:
    return (a[0] - b[0], a[1] - b[1])


def _scale(c: z3.ArithRef, a: Vec) -> Vec:
    return (c * a[0], c * a[1])


def _comb(a: Vec, b: Vec, t: z3.ArithRef) -> Vec:
    """(1 - t) a + t b."""
    return ((1 - t) * a[0] + t * b[0], (1 - t) * a[1] + t * b[1])


def _veq(a: Vec, b: Vec) -> z3.BoolRef:
    return z3.And(a[0] == b[0], a[1] == b[1])


def N2(v: Vec) -> z3.ArithRef:
    """|v|^2, abstract: ``concrete`` makes it v.x^2 + v.y^2."""
    return _SQ(v[0], v[1])


def DOT(a: Vec, b: Vec) -> z3.ArithRef:
    return _DT(a[0], a[1], b[0], b[1])


_COS = z3.Function("Cos", _R, _R)
_SIN = z3.Function("Sin", _R, _R)


def e(x: z3.ArithRef) -> Vec:
    """(cos x, sin x)."""
    return (_COS(x), _SIN(x))


def _rot(cs: Vec, v: Vec) -> Vec:
    """v turned by the angle whose (cos, sin) is cs."""
    return (cs[0] * v[0] - cs[1] * v[1], cs[1] * v[0] + cs[0] * v[1])


def _unit(cs: Vec) -> z3.BoolRef:
    """(cos, sin) on the unit circle, |cs|^2 = 1 (abstract norm: concrete, c^2 + s^2 = 1)."""
    return N2(cs) == 1


def _sum_rule(t: Vec, x: Vec, y: Vec) -> z3.BoolRef:
    """e(x + y) = e(x) e(y) on values: t is (cos, sin) of x + y."""
    return z3.And(t[0] == x[0] * y[0] - x[1] * y[1], t[1] == x[1] * y[0] + x[0] * y[1])


def _diff_rule(t: Vec, x: Vec, y: Vec) -> z3.BoolRef:
    """e(x - y) from e(x), e(y)."""
    return z3.And(t[0] == x[0] * y[0] + x[1] * y[1], t[1] == x[1] * y[0] - x[0] * y[1])


def _same(a: z3.ArithRef, b: z3.ArithRef) -> None:
    """a and b are the same real for every value of their names (else the fact is not one)."""
    if z3.is_true(z3.simplify(a == b)):
        return
    s = z3.Solver()
    s.set("timeout", 2000)
    s.add(a != b)
    if s.check() != z3.unsat:
        raise ValueError(f"not an identity: {a} = {b}")


# The ledger's trigonometric facts (A3), each at the points given; ``at`` names them.
def a3_unit(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos^2 + sin^2 = 1 at {at}", _unit(e(x)))


def a3_sum(total: z3.ArithRef, x: z3.ArithRef, y: z3.ArithRef, at: str) -> Hyp:
    _same(total, x + y)
    return (f"A3 cos, sin of a sum at {at}", _sum_rule(e(total), e(x), e(y)))


def a3_diff(total: z3.ArithRef, x: z3.ArithRef, y: z3.ArithRef, at: str) -> Hyp:
    _same(total, x - y)
    return (f"A3 cos, sin of a difference at {at}", _diff_rule(e(total), e(x), e(y)))


def a3_cos_bound(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos x >= 1 - x^2/2 at {at}", _COS(x) >= 1 - x * x / 2)


def a3_cos_mono(x: z3.ArithRef, y: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos even, non-increasing on [0, pi], at {at}",
            z3.Implies(z3.And(-y <= x, x <= y, y <= G_MAX), _COS(x) >= _COS(y)))


def a3_sin_nonneg(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 sin >= 0 on [0, pi] at {at}",
            z3.Implies(z3.And(0 <= x, x <= G_MAX), _SIN(x) >= 0))


def a3_cos_nonneg(x: z3.ArithRef, at: str) -> Hyp:
    return (f"A3 cos >= 0 on [0, pi/2] at {at}",
            z3.Implies(z3.And(0 <= x, 2 * x <= G_MAX), _COS(x) >= 0))


# --- lemmas and their use by substitution ----------------------------------------------------

#: A lemma's trigonometric facts (A3, assumed at any point): a proof that uses the lemma carries
#: them, substituted, into its own hypotheses. Its instances of other proved lemmas ("by ...")
#: are not carried: they hold wherever the norms mean |v|^2 and the dot product, where the
#: user's conclusion is read.
_CARRIED = ("A3 ",)
_PROVED = "by "

Pairs = Sequence[tuple[z3.ExprRef, z3.ExprRef]]


@dataclass(frozen=True)
class Lemma:
    """A proved VC and the form a proof instantiates: ``hyps``/``goal`` in abstract norms
    (``vc`` holds them concrete unless the lemma is abstract: its VC is then proved for every
    sq, dt). ``names`` are its free names, by key, for ``at``."""

    vc: VC
    hyps: tuple[Hyp, ...]
    goal: z3.BoolRef
    names: tuple[tuple[str, object], ...] = ()

    def use(self, pairs: Pairs, at: str) -> list[Hyp]:
        """The hypotheses a proof adds to use this lemma at ``pairs`` (names -> terms): its
        trigonometric facts, substituted, and the lemma instantiated under its other premises.
        Sound: the lemma's VC is proved with those facts and its instances of proved lemmas
        as hypotheses, and the instances hold where the norms are |v|^2 (for an abstract
        lemma) or are none (for a concrete one)."""
        sub = (lambda f: z3.substitute(f, *pairs)) if pairs else (lambda f: f)
        carried = [(n, h) for n, h in self.hyps if n.startswith(_CARRIED)]
        rest = [h for n, h in self.hyps if not n.startswith(_CARRIED + (_PROVED,))]
        out = [(f"{n} [{at}]", sub(h)) for n, h in carried]
        body = z3.Implies(z3.And(rest), self.goal) if rest else self.goal
        out.append((f"by {self.vc.name} at {at}", sub(body)))
        return out

    def at(self, at: str, **terms: object) -> list[Hyp]:
        """``use`` with the free names given by key (a vector name takes a pair of terms)."""
        names = dict(self.names)
        unknown = set(terms) - set(names)
        if unknown:
            raise KeyError(f"{self.vc.name} has no names {sorted(unknown)}")
        return self.use(_pairs(*[(names[k], v) for k, v in terms.items()]), at)

    def term(self, f: z3.ExprRef, **terms: object) -> z3.ExprRef:
        """A term in this lemma's names, at ``terms``."""
        names = dict(self.names)
        pairs = _pairs(*[(names[k], v) for k, v in terms.items()])
        return z3.substitute(f, *pairs) if pairs else f


def lemma(name: str, hyps: Sequence[Hyp], goal: z3.BoolRef, key: str, *, abstract: bool = False,
          names: dict[str, object] | None = None, witness: Pairs = (),
          counter_witness: Pairs = ()) -> Lemma:
    hyps = _dedupe(hyps)
    if key not in [n for n, _ in hyps]:
        raise KeyError(f"{name}: no hypothesis {key!r}")
    if abstract:
        vc = VC(name, hyps, goal, key_premise=key, witness=tuple(witness),
                counter_witness=tuple(counter_witness))
    else:
        vc = VC(name, tuple((n, concrete(h)) for n, h in hyps), concrete(goal), key_premise=key,
                witness=tuple(witness), counter_witness=tuple(counter_witness))
    return Lemma(vc, hyps, goal, tuple((names or {}).items()))


def _dedupe(hyps: Sequence[Hyp]) -> tuple[Hyp, ...]:
    out: list[Hyp] = []
    seen: list[z3.BoolRef] = []
    for n, h in hyps:
        if any(z3.eq(h, s) for s in seen):
            continue
        seen.append(h)
        out.append((" ".join(n.split()), h))
    return tuple(out)


def _pairs(*groups: tuple[object, object]) -> list[tuple[z3.ExprRef, z3.ExprRef]]:
    """Substitution pairs; a vector pairs component by component."""
    out: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    for name, term in groups:
        if isinstance(name, tuple):
            out += list(zip(name, term))  # type: ignore[arg-type]
        else:
            out.append((name, term))  # type: ignore[arg-type]
    return out


def _obligation_vc(ident: str, vc_name: str, obligations: Sequence[Obligation]) -> VC:
    """A VC of another obligation, as the prove run discharges it."""
    ob = next(o for o in obligations if o.id == ident)
    q = ob.build()
    assert isinstance(q, Z3Query)
    return next(v for v in q.vcs if v.name == vc_name)


# --- Margin.arc_chord, as proved ---------------------------------------------------------------

def abstract_norms(f: z3.ExprRef) -> z3.ExprRef:
    """f with every a*a + b*b (as Margin's _n2 builds it) written sq(a, b)."""
    if z3.is_add(f) and f.num_args() == 2:
        a, b = f.arg(0), f.arg(1)
        if (z3.is_mul(a) and z3.is_mul(b) and a.num_args() == 2 and b.num_args() == 2
                and z3.eq(a.arg(0), a.arg(1)) and z3.eq(b.arg(0), b.arg(1))):
            return _SQ(abstract_norms(a.arg(0)), abstract_norms(b.arg(0)))
    if z3.is_app(f) and f.num_args() > 0:
        return f.decl()(*[abstract_norms(c) for c in f.children()])
    return f


@dataclass(frozen=True)
class ArcChord:
    """Margin.arc_chord's VC (its names r, g, c = cos(g/2), s = sin(g/2), c_psi, s_psi) and the
    parts of its goal the other lemmas use: the chord weight t, the bound delta (r g^2/8 as
    proved) and m - q, the point minus its chord point, in abstract norms."""

    vc: VC
    r: z3.ArithRef
    g: z3.ArithRef
    c: z3.ArithRef
    s: z3.ArithRef
    cp: z3.ArithRef
    sp: z3.ArithRef
    t: z3.ArithRef
    delta: z3.ArithRef
    mq: Vec

    def lemma(self) -> Lemma:
        hyps = tuple((n, abstract_norms(h)) for n, h in self.vc.hypotheses)
        goal = abstract_norms(self.vc.goal)
        pairs = [(h[1], h0[1]) for h, h0 in zip(hyps, self.vc.hypotheses)] + [(goal, self.vc.goal)]
        if not all(z3.eq(concrete(a), b) for a, b in pairs):
            raise ValueError("Margin.arc_chord does not read back from abstract norms")
        return Lemma(self.vc, hyps, goal)

    def delta_at(self, radius: z3.ArithRef, turn: z3.ArithRef) -> z3.ArithRef:
        """The lemma's bound for a point at ``radius`` turning through ``turn``."""
        return z3.substitute(self.delta, (self.r, radius), (self.g, turn))


def arc_chord(vc: VC | None = None) -> ArcChord:
    """Margin.arc_chord as the prove run has it (or ``vc``, a mutant for the tests)."""
    if vc is None:
        vc = _obligation_vc("Margin.arc_chord", "arc_within_chord", margin_obligations())
    r, g, c, s, cp, sp = z3.Reals("r g c s c_psi s_psi")
    goal = abstract_norms(vc.goal)
    bad = ValueError("Margin.arc_chord's goal is not 0 <= t <= 1 and |m - q|^2 <= delta^2")
    if not (z3.is_and(goal) and goal.num_args() == 3):
        raise bad
    lo, hi, bound = goal.children()
    t = hi.arg(0)
    lhs, rhs = bound.arg(0), bound.arg(1)
    if not (z3.is_le(hi) and z3.is_ge(lo) and z3.eq(lo.arg(0), t) and z3.is_le(bound)
            and lhs.decl().eq(_SQ) and z3.is_mul(rhs) and rhs.num_args() == 2
            and z3.eq(rhs.arg(0), rhs.arg(1))):
        raise bad
    return ArcChord(vc, r, g, c, s, cp, sp, t, rhs.arg(0), (lhs.arg(0), lhs.arg(1)))


def arc_steps(arc: ArcChord, k: dict[str, Lemma]) -> dict[str, Lemma]:
    """Margin.arc_chord's goal in three lemmas over its own names and premises (each decided
    by both solvers alone, where the whole is Z3-only): the chord weight lies in [0, 1]
    (arc_weight), the point is r (c_psi - c) from its chord point (arc_dist), and
    0 <= r (c_psi - c) <= delta (arc_gap, where delta's constant is paid: cos x >= 1 - x^2/2).
    The fourth, named Margin.arc_chord, is its re-proof here: its premises, the three lemmas
    and square_monotone at its names give its own goal, unchanged."""
    facts = arc.vc.hypotheses
    key = arc.vc.key_premise or facts[0][0]
    gap = arc.r * (arc.cp - arc.c)
    mq = (concrete(arc.mq[0]), concrete(arc.mq[1]))
    dist = mq[0] * mq[0] + mq[1] * mq[1]
    wit = arc.vc.witness
    out = {
        "arc_weight": lemma("arc_weight", facts, z3.And(0 <= arc.t, arc.t <= 1), key,
                            witness=wit),
        "arc_dist": lemma("arc_dist", facts, dist == gap * gap, key, witness=wit),
        "arc_gap": lemma("arc_gap", facts, z3.And(0 <= gap, gap <= arc.delta), key,
                         witness=wit),
    }
    hyps = list(facts)
    for name in ("arc_weight", "arc_dist", "arc_gap"):
        hyps += out[name].use((), "Margin.arc_chord's names")
    hyps += k["square_monotone"].at("r (c_psi - c) <= delta", a=gap, b=arc.delta, m=dist)
    out["Margin.arc_chord"] = lemma("Margin.arc_chord", hyps, arc.vc.goal, key, witness=wit,
                                    counter_witness=arc.vc.counter_witness)
    return out


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


def _occurs(term: z3.ExprRef, inside: z3.ExprRef) -> bool:
    if z3.eq(term, inside):
        return True
    return any(_occurs(term, c) for c in inside.children())


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
                                                "X0 X1 X2 A B K00 K01 K10 K11".split())
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
    lo1, hi1, th1, A1, g1 = z3.Reals("lk2.lo1 lk2.hi1 lk2.theta1 lk2.A1 lk2.g1")
    lo2, hi2, th2, A2, g2 = z3.Reals("lk2.lo2 lk2.hi2 lk2.theta2 lk2.A2 lk2.g2")
    rb = l1 + re
    L1 = lattice("lk2.joint1", lo1, hi1, th1, A1, g1)
    L2 = lattice("lk2.joint2", lo2, hi2, th2, A2, g2)
    t1c, t2c = L1.theta_c, L2.theta_c
    c1, G1, c2, G2 = L1.c, L1.G, L2.c, L2.G
    c1e = c1 + G1

    def P(alpha: z3.ArithRef, phi: z3.ArithRef) -> Vec:
        return _point2(b, l1, alpha, phi, u, v)
    alphas = (c1, c1, c1e, c1e)
    phis = (c1 + c2, (c1 + c2) + G2, c1e + c2, (c1e + c2) + G2)
    # The points, named by their definitions: the link's point at theta, after snapping theta1
    # (X1) and theta2 (X2), the chord's ends A, B about the base, the cell's corners K.
    at = [("X0", th1, th1 + th2, "theta"), ("X1", t1c, t1c + th2, "(theta1', theta2)"),
          ("X2", t1c, t1c + t2c, "theta'"), ("A", c1, c1 + t2c, "(c1, theta2')"),
          ("B", c1e, c1e + t2c, "(c1 + G1, theta2')")]
    at += [(f"K{i}", a, ph, f"corner {i}") for i, (a, ph) in enumerate(zip(alphas, phis))]
    pts = {n: _v(f"lk2.{n}") for n, *_ in at}
    X0, X1, X2, A, B = (pts[n] for n in ("X0", "X1", "X2", "A", "B"))
    Ks = [pts[f"K{i}"] for i in range(4)]
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
    hyps += L1.defs + L2.defs
    hyps += k["lattice"].at("joint 1", lo=lo1, hi=hi1, theta=th1, A=A1, g=g1, **L1.names())
    hyps += k["lattice"].at("joint 2", lo=lo2, hi=hi2, theta=th2, A=A2, g=g2, **L2.names())
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


# --- (a) the principal in its layer's box ------------------------------------------------------

def _mn(a: z3.ArithRef, b: z3.ArithRef) -> z3.ArithRef:
    return z3.If(a <= b, a, b)


def _mx(a: z3.ArithRef, b: z3.ArithRef) -> z3.ArithRef:
    return z3.If(a <= b, b, a)


def _abs(a: z3.ArithRef) -> z3.ArithRef:
    return z3.If(a >= 0, a, -a)


@dataclass(frozen=True)
class Principal:
    """The principal's PTP motion (docs/model.md §2) over symbolic start, goal, omega, dt."""

    start: Vec
    goal: Vec
    omega: Vec
    dt: z3.ArithRef
    Tf: z3.ArithRef
    N: z3.ArithRef

    @classmethod
    def named(cls) -> Principal:
        return cls(_v("L.start"), _v("L.goal"), _v("L.omega"), z3.Real("dt"), z3.Real("Tf"),
                   Z3Dims.named().N)

    def theta(self, t: z3.ArithRef) -> Vec:
        """spec.ptp_angles (spec.left_angles' motion) run on the symbols."""
        return ptp_angles(self.start, self.goal, self.Tf, t)

    def tf_def(self) -> Hyp:
        tf, _ = counts_on_terms(self.start, self.goal, self.omega, self.dt)
        return ("Tf = max_q |goal_q - start_q| / omega_q (spec.exact_tf)", self.Tf == tf)

    def n_def(self) -> Hyp:
        tf, n = counts_on_terms(self.start, self.goal, self.omega, self.dt)
        # The code recomputes Tf inside exact_n: it is the named Tf (tf_def, a hypothesis).
        return ("N = max(1, ceil(Tf / dt)) (spec.exact_n)",
                self.N == z3.substitute(n, (tf, self.Tf)))

    def basics(self) -> tuple[Hyp, ...]:
        return (("dt > 0", self.dt > 0),
                ("omega_q > 0", z3.And(self.omega[0] > 0, self.omega[1] > 0)), self.tf_def())

    def box(self, variant: str, k: z3.ArithRef, *, sign_flip: bool = False) -> tuple[Vec, Vec]:
        """Layer k's box (k a real): spec.Variant.layer_box, the code's rule, run on the symbols
        (``sign_flip``, a test's mutant, points the modified box away from the goal)."""
        v = Variant(variant)
        if sign_flip:
            return v.layer_box(self.start, self.goal, self.omega, self.dt, self.Tf, k) if (
                v is not Variant.MODIFIED) else _flipped(self, k)
        return v.layer_box(self.start, self.goal, self.omega, self.dt, self.Tf, k)

    def rest_box(self, variant: str, **kw: bool) -> tuple[Vec, Vec]:
        """The rest layer's box: spec.Variant.rest_box (layer N-1's, or the goal for tight)."""
        v = Variant(variant)
        if kw.get("sign_flip") and v is Variant.MODIFIED:
            return _flipped(self, z3.ToReal(self.N) - 1)
        return v.rest_box(self.start, self.goal, self.omega, self.dt, self.Tf,
                          z3.ToReal(self.N))


def _exact(x: object, reading: str = "binary") -> object:
    """A reading of a number, on the proofs' symbols: the symbol is the reading's exact value."""
    return x


def counts_on_terms(start: Vec, goal: Vec, omega: Vec, dt: z3.ArithRef,
                    travel: Callable[..., object] | None = None
                    ) -> tuple[z3.ArithRef, z3.ArithRef]:
    """(Tf, N) as spec.exact_tf and spec.exact_n compute them (docs/model.md §2: the counts'
    one owner), their modules' own code run on the symbols (``module_on_terms``): a number's
    reading is the symbol itself, ``max`` an If, the exact ceiling ``spec.ceil_of`` (tested equal
    to the code's on fractions). ``travel`` replaces the travel time's function (the tests'
    mutant, from a planted copy of its module)."""
    from types import SimpleNamespace

    from ..spec import ceil_of, exact_tf
    from ._obl_tools import module_on_terms
    tt = travel or exact_tf.__globals__["travel_time"]
    counts = module_on_terms(tt, _read=_exact, ceil_fraction=ceil_of)
    grid = module_on_terms(exact_tf, travel_time=counts[tt.__name__],
                           time_steps=counts["time_steps"])
    s = SimpleNamespace(left=SimpleNamespace(start=start, goal=goal, omega=omega), dt=dt)
    return grid["exact_tf"](s), grid["exact_n"](s)


def _flipped(P: Principal, k: z3.ArithRef) -> tuple[Vec, Vec]:
    """The modified rule with s_q negated (the tests' mutant), through the same joint_box."""
    a = P.theta(k * P.dt)
    out = [Variant.MODIFIED.joint_box(a[q], a[q], P.omega[q] * P.dt,
                                      z3.Not(P.goal[q] > P.start[q])) for q in range(2)]
    return (out[0], out[1])


def in_box(theta: Vec, box: tuple[Vec, Vec]) -> z3.BoolRef:
    return z3.And(*[z3.And(box[q][0] <= theta[q], theta[q] <= box[q][1]) for q in range(2)])


def step_window(k: z3.ArithRef, t: z3.ArithRef, dt: z3.ArithRef) -> z3.BoolRef:
    K = z3.ToReal(k)
    return z3.And(K * dt <= t, t <= (K + 1) * dt)


def principal_steps(P: Principal) -> dict[str, Lemma]:
    """Small lemmas of (a), each decided by Z3 and by cvc5, that the motion and rest VCs use by
    substitution (cvc5 does not decide those VCs without them): the PTP fraction
    f(x) = spec.ptp_fraction(x, Tf) moves forward by at most dt / Tf over a window of dt
    (frac_step); the travel time bounds each joint's travel (travel); a joint's displacement
    over a forward step of the fraction is within omega_q dt, with the travel's sign (step_q);
    N dt covers Tf (n_covers), and from N dt on the fraction is 1 (at_rest)."""
    Tf, dt, om = P.Tf, P.dt, P.omega
    d = [P.goal[q] - P.start[q] for q in range(2)]
    a, b, x, t = z3.Reals("fs.a fs.b st.x ar.t")
    N = z3.ToReal(P.N)

    def f(y: z3.ArithRef) -> z3.ArithRef:
        return ptp_fraction(y, Tf)
    out: dict[str, Lemma] = {}
    key = "0 <= a <= b <= a + dt"
    out["frac_step"] = lemma(
        "frac_step", (("dt > 0", dt > 0), ("Tf >= 0", Tf >= 0),
                      (key, z3.And(0 <= a, a <= b, b <= a + dt))),
        z3.And(f(a) <= f(b), (f(b) - f(a)) * Tf <= dt, 0 <= f(a), f(b) <= 1), key,
        names=dict(a=a, b=b))
    travel = z3.And(Tf >= 0, *[z3.And(d[q] <= om[q] * Tf, -d[q] <= om[q] * Tf) for q in range(2)])
    tf = P.tf_def()
    out["travel"] = lemma("travel", (("omega_q > 0", z3.And(om[0] > 0, om[1] > 0)), tf), travel,
                          tf[0])
    for q in range(2):
        kq = "x Tf <= dt"
        out[f"step{q + 1}"] = lemma(
            f"step{q + 1}", (("omega_q > 0", om[q] > 0), ("dt > 0", dt > 0),
                             ("travel (Tf >= 0, |goal_q - start_q| <= omega_q Tf)",
                              z3.And(Tf >= 0, d[q] <= om[q] * Tf, -d[q] <= om[q] * Tf)),
                             ("x >= 0", x >= 0), (kq, x * Tf <= dt)),
            z3.And(d[q] * x <= om[q] * dt, -(d[q] * x) <= om[q] * dt,
                   z3.Implies(d[q] >= 0, d[q] * x >= 0), z3.Implies(d[q] <= 0, d[q] * x <= 0)),
            kq, names=dict(x=x))
    nd = P.n_def()
    out["n_covers"] = lemma("n_covers", (("dt > 0", dt > 0), ("Tf >= 0", Tf >= 0), nd),
                            z3.And(N * dt >= Tf, P.N >= 1), nd[0])
    kr = "t >= N dt"
    out["at_rest"] = lemma("at_rest", (("dt > 0", dt > 0), ("Tf >= 0", Tf >= 0),
                                       ("N dt >= Tf, N >= 1", z3.And(N * dt >= Tf, P.N >= 1)),
                                       (kr, t >= N * dt)),
                           z3.And(f(t) == 1, f(N * dt) == 1), kr, names=dict(t=t))
    return out


def _step_instances(steps: dict[str, Lemma], P: Principal, lo: z3.ArithRef, hi: z3.ArithRef,
                    at: str) -> list[Hyp]:
    """frac_step over [lo, hi] and step_q at the fraction's advance there."""
    adv = ptp_fraction(hi, P.Tf) - ptp_fraction(lo, P.Tf)
    out = steps["frac_step"].at(at, a=lo, b=hi)
    for q in (1, 2):
        out += steps[f"step{q}"].at(at, x=adv)
    return out


def principal_lemmas(variant: str, *, sign_flip: bool = False,
                     n_def: Hyp | None = None) -> tuple[Lemma, Lemma]:
    """(a) for ``variant``: the motion in layer k's box over [k dt, (k+1) dt], and in the rest
    layer's box from N dt on, each using principal_steps' lemmas by substitution.
    ``sign_flip`` and ``n_def`` are the tests' mutants."""
    P = Principal.named()
    steps = principal_steps(P)
    k, t = z3.Int("k"), z3.Real("t")
    K = z3.ToReal(k)
    key = "k dt <= t <= (k+1) dt"
    used = list(steps["travel"].at("the travel time"))
    for lo, hi, at in ((K * P.dt, t, "[k dt, t]"), (t, (K + 1) * P.dt, "[t, (k+1) dt]")):
        used += _step_instances(steps, P, lo, hi, at)
    used += steps["frac_step"].at("[k dt, (k+1) dt]", a=K * P.dt, b=(K + 1) * P.dt)
    motion = lemma("motion", P.basics() + (("k >= 0", k >= 0), (key, step_window(k, t, P.dt)))
                   + tuple(used),
                   in_box(P.theta(t), P.box(variant, K, sign_flip=sign_flip)), key,
                   names=dict(k=k, t=t))
    nd = n_def or P.n_def()
    N = z3.ToReal(P.N)
    used = list(steps["travel"].at("the travel time"))
    used += steps["n_covers"].at("N")
    used += steps["at_rest"].at("t", t=t)
    used += _step_instances(steps, P, (N - 1) * P.dt, N * P.dt, "[(N-1) dt, N dt]")
    rest = lemma("rest", P.basics() + (nd, ("t >= N dt", t >= N * P.dt)) + tuple(used),
                 in_box(P.theta(t), P.rest_box(variant, sign_flip=sign_flip)), nd[0],
                 names=dict(t=t))
    return motion, rest


# --- (b) the subordinate in its cell's box -----------------------------------------------------

@dataclass(frozen=True)
class Subordinate:
    lo: Vec
    h: Vec

    @classmethod
    def named(cls) -> Subordinate:
        return cls(_v("R.lo"), _v("R.h"))

    def angle(self, c: tuple[z3.ArithRef, z3.ArithRef]) -> Vec:
        return (self.lo[0] + z3.ToReal(c[0]) * self.h[0], self.lo[1] + z3.ToReal(c[1]) * self.h[1])

    def box(self, c: tuple[z3.ArithRef, z3.ArithRef]) -> tuple[Vec, Vec]:
        """spec.cell_box (spec.right_box's rule) run on the symbols."""
        return cell_box(self.lo, self.h, (z3.ToReal(c[0]), z3.ToReal(c[1])))

    def theta(self, c: tuple[z3.ArithRef, z3.ArithRef], c2: tuple[z3.ArithRef, z3.ArithRef],
              k: z3.ArithRef, t: z3.ArithRef, dt: z3.ArithRef) -> Vec:
        """The linear move in joint space from c (at k dt) to c2 (at (k+1) dt)."""
        f = (t - z3.ToReal(k) * dt) / dt
        a, b = self.angle(c), self.angle(c2)
        return (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))


def subordinate_lemmas(*, reach: int = 1) -> tuple[Lemma, Lemma]:
    """(b): a move to a neighbour stays in the cell's box; on a valid path every step is one
    (a wait once the list has ended). ``reach`` is the tests' mutant (2: a jump of two cells)."""
    S = Subordinate.named()
    dt, t = z3.Real("dt"), z3.Real("t")
    k = z3.Int("k")
    c, c2 = (z3.Int("c.i"), z3.Int("c.j")), (z3.Int("c'.i"), z3.Int("c'.j"))
    key = "c' a neighbour of c: |c'_q - c_q| <= 1"
    hyps = (("dt > 0", dt > 0), ("h_q > 0", z3.And(S.h[0] > 0, S.h[1] > 0)), ("k >= 0", k >= 0),
            ("k dt <= t <= (k+1) dt", step_window(k, t, dt)),
            (key, z3.And(abs_int(c2[0] - c[0]) <= reach, abs_int(c2[1] - c[1]) <= reach)))
    move = lemma("neighbour_move", hyps, in_box(S.theta(c, c2, k, t, dt), S.box(c)), key,
                 names=dict(c=c, c2=c2, k=k, t=t))
    d = Z3Dims.named()
    ints = z3.IntSort()
    P = z3.Array("P", ints, ints, ints, ints)
    start, goal = (z3.Int("start.i"), z3.Int("start.j")), (z3.Int("goal.i"), z3.Int("goal.j"))
    L = z3_path("L")
    key2 = "is_path L (fixed, docs/model.md §5)"
    here, nxt = position(L, k), position(L, k + 1)
    hyps2 = (("N >= 1, m, n >= 1", d.sane()),
             ("start, goal in the grid", z3.And(in_grid(d, start), in_grid(d, goal))),
             (key2, is_path_fixed(P, d, start, goal, L)), ("k >= 0", k >= 0))
    goal2 = z3.And(in_grid(d, here), adjacent(here, nxt),
                   z3.Implies(k + 1 >= L.length, z3.And(here[0] == goal[0], here[1] == goal[1],
                                                        nxt[0] == goal[0], nxt[1] == goal[1])))
    on_path = lemma("on_path", hyps2, goal2, key2, names=dict(k=k))
    return move, on_path


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


# --- (e) the composition -------------------------------------------------------------------------

def _step_lemma() -> Lemma:
    """The time-layer decomposition: t >= 0 lies in the step k = floor(t / dt)."""
    dt, t = z3.Reals("dt t")
    k, N = z3.Int("st.k"), z3.Int("st.N")
    key = "t >= 0"
    hyps = (("dt > 0", dt > 0), (key, t >= 0), ("k = floor(t / dt)", k == z3.ToInt(t / dt)))
    goal = z3.And(k >= 0, step_window(k, t, dt), z3.Implies(k >= N, z3.ToReal(N) * dt <= t))
    return lemma("time_step", hyps, goal, key, names=dict(k=k, N=N, t=t))


def _regions(variant: str) -> tuple[Callable[..., z3.ExprRef], Callable[..., z3.ExprRef],
                                    Callable[..., z3.ExprRef]]:
    """The principal's region of link a at layer k, its rest region, and the subordinate's
    region of link b at cell (i, j): opaque values, as in Theorems 1 and 3."""
    ints = z3.IntSort()
    region_l = z3.Function(f"regionL_{variant}", ints, ints, REGION)
    region_r = z3.Function("regionR", ints, ints, ints, REGION)
    N = Z3Dims.named().N
    if variant == "tight":
        region_rest = z3.Function("regionRest_tight", ints, REGION)

        def rest(a: z3.ArithRef) -> z3.ExprRef:
            return region_rest(a)
    else:
        def rest(a: z3.ArithRef) -> z3.ExprRef:
            return region_l(N - 1, a)     # the paper's: layer N-1's region
    return (lambda k, a: region_l(k, a)), rest, (lambda i, j, b: region_r(i, j, b))


LINKS = (0, 1)
#: Every part of an arm (docs/model.md §2): links 1 and 2 and, if the arm carries one, the tool
#: (part 3, index 2), each the prism of its planar outline over its height interval.
TOOL = 2
PARTS = (0, 1, TOOL)
#: solid(x, theta1, theta2, p1, p2, z): the point (p, z) of 3-D space lies in the prism of part x
#: at theta (opaque: its outline and its heights are premises).
_SOLID_L = z3.Function("solidL", z3.IntSort(), *[_R] * 5, z3.BoolSort())
_SOLID_R = z3.Function("solidR", z3.IntSort(), *[_R] * 5, z3.BoolSort())


@dataclass(frozen=True)
class Heights:
    """One arm's tool and heights, symbolic (docs/model.md §2): whether it carries a tool, and
    for each part whether it has a height interval and the interval."""

    tag: str
    has_tool: z3.BoolRef
    has_z: tuple[z3.BoolRef, ...]
    z: tuple[tuple[z3.ArithRef, z3.ArithRef], ...]

    @classmethod
    def named(cls, tag: str) -> Heights:
        return cls(tag, z3.Bool(f"{tag}.has_tool"),
                   tuple(z3.Bool(f"{tag}.has_z{x + 1}") for x in PARTS),
                   tuple((z3.Real(f"{tag}.z{x + 1}.lo"), z3.Real(f"{tag}.z{x + 1}.hi"))
                         for x in PARTS))

    def present(self, x: int) -> z3.BoolRef:
        return self.has_tool if x == TOOL else z3.BoolVal(True)

    def solid(self, x: int, theta: Vec, p: Vec, z: z3.ArithRef) -> z3.BoolRef:
        f = _SOLID_L if self.tag == "L" else _SOLID_R
        return f(x, theta[0], theta[1], p[0], p[1], z)

    def link(self, x: int, theta: Vec, p: Vec) -> z3.BoolRef:
        return (link_l if self.tag == "L" else link_r)(x, theta, p)

    def outline(self, theta: Vec, p: Vec, z: z3.ArithRef) -> z3.BoolRef:
        """A point of part x's prism lies over a point of its planar outline; an arm without a
        tool has no part 3."""
        return z3.And([z3.Implies(self.solid(x, theta, p, z), z3.And(
            self.link(x, theta, p), self.present(x))) for x in PARTS])

    def prism(self, theta: Vec, p: Vec, z: z3.ArithRef) -> z3.BoolRef:
        """Definitional (docs/model.md §2): the prism of part x is its outline over its closed
        height interval (every height without one)."""
        return z3.And([z3.Implies(self.solid(x, theta, p, z), z3.And(
            self.link(x, theta, p), self.present(x),
            z3.Implies(self.has_z[x], z3.And(self.z[x][0] <= z, z <= self.z[x][1]))))
            for x in PARTS])


def heights_kept(hl: Heights, hr: Heights, x: int, y: int,
                 overlap: Callable[..., object] | None = None) -> z3.BoolRef:
    """spec.heights_overlap (or ``overlap``, the tests' mutant) on the two parts' intervals, read
    off its syntax tree and run on the terms (Safety.height_rule's reading), for each case of
    "has an interval" (None where not)."""
    from ..spec import heights_overlap
    from ._obl_tools import _bool, run_on_terms
    fn = overlap or heights_overlap

    def ov(a: object, b: object) -> z3.BoolRef:
        return _bool(run_on_terms(fn, a, b), 0)
    a, b = hl.z[x], hr.z[y]
    return z3.If(hl.has_z[x], z3.If(hr.has_z[y], ov(a, b), ov(a, None)),
                 z3.If(hr.has_z[y], ov(None, b), ov(None, None)))


def pair_kept(hl: Heights, hr: Heights, x: int, y: int,
              overlap: Callable[..., object] | None = None) -> z3.BoolRef:
    """Whether BuiltDR tests the pair (spec.pairs_to_test: both parts present, their heights
    overlapping; Safety.height_rule checks pairs_to_test against heights_overlap)."""
    return z3.And(hl.present(x), hr.present(y), heights_kept(hl, hr, x, y, overlap))


HEIGHT_HYP = ("Safety.height_rule at the pairs the height test drops: no point of 3-D space in "
              "both prisms")


def height_hypothesis(at: _At, overlap: Callable[..., object] | None = None) -> z3.BoolRef:
    """The height rule as the compositions use it, at the instant's configurations and the point
    (p, z): a pair of parts whose intervals heights_overlap calls disjoint shares no point.
    ``height_instance_vc`` derives it from the prisms' definition."""
    hl, hr = Heights.named("L"), Heights.named("R")
    return z3.And([z3.Implies(z3.Not(heights_kept(hl, hr, x, y, overlap)), z3.Not(z3.And(
        hl.solid(x, at.theta_l, at.p, at.z), hr.solid(y, at.theta_r, at.p, at.z))))
        for x in PARTS for y in PARTS])


def height_instance_vc(overlap: Callable[..., object] | None = None) -> VC:
    """The compositions' height hypothesis holds for the prisms (docs/model.md §2: a part is the
    prism of its outline over its closed height interval), with the pairs read by the code's
    interval test run on terms: Safety.height_rule at the parts of both arms. ``overlap`` is
    the tests' mutant (``<`` for ``<=``: refuted at touching ends)."""
    at = _At.named()
    hl, hr = Heights.named("L"), Heights.named("R")
    key = "the prisms (docs/model.md §2): a part's outline over its closed height interval"
    hyps: list[Hyp] = [
        (key, z3.And(hl.prism(at.theta_l, at.p, at.z), hr.prism(at.theta_r, at.p, at.z))),
    ]
    def at_heights(right: tuple[int, int]) -> tuple[tuple[z3.ExprRef, z3.ExprRef], ...]:
        """Tools on both arms, the principal's parts at [0, 1], the subordinate's at ``right``."""
        out: list[tuple[z3.ExprRef, z3.ExprRef]] = []
        for h, (lo, hi) in ((hl, (0, 1)), (hr, right)):
            out += [(h.has_tool, z3.BoolVal(True))]
            for x in PARTS:
                out += [(h.has_z[x], z3.BoolVal(True)), (h.z[x][0], z3.RealVal(lo)),
                        (h.z[x][1], z3.RealVal(hi))]
        return tuple(out)
    # Vacuity: touching intervals (every pair kept); without the key: [0, 1] and [2, 3] apart.
    return VC("height_instances", tuple(hyps), height_hypothesis(at, overlap), key_premise=key,
              witness=at_heights((1, 2)), counter_witness=at_heights((2, 3)))


@dataclass(frozen=True)
class _At:
    """The instant, the cells, the configurations and the point the composition reasons at."""

    P: Principal
    S: Subordinate
    d: Z3Dims
    k: z3.ArithRef
    here: tuple[z3.ArithRef, z3.ArithRef]
    theta_l: Vec
    theta_r: Vec
    p: Vec
    z: z3.ArithRef

    @classmethod
    def named(cls) -> _At:
        P, S, d = Principal.named(), Subordinate.named(), Z3Dims.named()
        L, k, t = z3_path("L"), z3.Int("kk"), z3.Real("t")
        here, nxt = position(L, k), position(L, k + 1)
        return cls(P, S, d, k, here, P.theta(t), S.theta(here, nxt, k, t, P.dt), _v("p"),
                   z3.Real("z"))


def region_hypotheses(variant: str, at: _At) -> list[Hyp]:
    """(c) as the compositions use it: the links of both arms, at the instant's configurations
    and the point, lie in the regions of their boxes (layer k's, the rest layer's, the cell's).
    ``region_instance_vc`` proves each an instance of ``region_statement``."""
    region_l, region_rest, region_r = _regions(variant)
    P, k, p, theta_l, theta_r, here = at.P, at.k, at.p, at.theta_l, at.theta_r, at.here
    box_k = P.box(variant, z3.ToReal(k))
    return [
        ("(c) Safety.region_soundness: links 1 and 2 of the principal at theta_L(t) "
         "in layer k's regions (its box, k < N; at p)",
         z3.And([z3.Implies(z3.And(0 <= k, k < at.d.N, in_box(theta_l, box_k)),
                            z3.Implies(link_l(x, theta_l, p), member(region_l(k, x), p)))
                 for x in LINKS])),
        ("(c) Safety.region_soundness: links 1 and 2 of the principal at theta_L(t) "
         "in the rest regions (its box; at p)",
         z3.And([z3.Implies(in_box(theta_l, P.rest_box(variant)),
                            z3.Implies(link_l(x, theta_l, p), member(region_rest(x), p)))
                 for x in LINKS])),
        ("(c) Safety.region_soundness: links 1 and 2 of the subordinate at theta_R(t) "
         "in the regions of its cell (its box; at p)",
         z3.And([z3.Implies(z3.And(in_grid(at.d, here), in_box(theta_r, at.S.box(here))),
                            z3.Implies(link_r(x, theta_r, p),
                                       member(region_r(here[0], here[1], x), p)))
                 for x in LINKS])),
        ("(c) Safety.tool_region: the principal's tool at theta_L(t) in layer k's region (its "
         "box, k < N; at p)",
         z3.Implies(z3.And(0 <= k, k < at.d.N, in_box(theta_l, box_k), link_l(TOOL, theta_l, p)),
                    member(region_l(k, TOOL), p))),
        ("(c) Safety.tool_region: the principal's tool at theta_L(t) in the rest region (its "
         "box; at p)",
         z3.Implies(z3.And(in_box(theta_l, P.rest_box(variant)), link_l(TOOL, theta_l, p)),
                    member(region_rest(TOOL), p))),
        ("(c) Safety.tool_region: the subordinate's tool at theta_R(t) in the region of its "
         "cell (its box; at p)",
         z3.Implies(z3.And(in_grid(at.d, here), in_box(theta_r, at.S.box(here)),
                           link_r(TOOL, theta_r, p)),
                    member(region_r(here[0], here[1], TOOL), p))),
    ]


#: swept(x, lo1, hi1, lo2, hi2, A1, A2, g1, g2): the region impl.swept_region builds for link x,
#: the box [lo1, hi1] x [lo2, hi2], the lattice anchored at (A1, A2) with spacings (g1, g2).
_SWEPT_L = z3.Function("sweptL", z3.IntSort(), *[_R] * 8, REGION)
_SWEPT_R = z3.Function("sweptR", z3.IntSort(), *[_R] * 8, REGION)

Box = tuple[Vec, Vec]


def _swept(f: z3.FuncDeclRef, x: z3.ArithRef | int, box: Box, anchor: Vec, g: Vec
           ) -> z3.ExprRef:
    return f(x, box[0][0], box[0][1], box[1][0], box[1][1], anchor[0], anchor[1], g[0], g[1])


def spacing_ok(g: Vec) -> z3.BoolRef:
    """The margin lemma's range of lattice spacings, 0 < g_q <= 157/50 (the loader's check)."""
    return z3.And(0 < g[0], g[0] <= G_MAX, 0 < g[1], g[1] <= G_MAX)


@dataclass(frozen=True)
class ArmModel:
    """One arm's links as the safety theorem reads them (docs/model.md §2, §4.2): the base b,
    the lengths l1, l2, the half-widths r1, r2 (w/2), R_base of link 1 and R_elbow of link 2
    (square roots, named), the opaque predicate "p is a point of link x at theta" (``link``),
    the region built for a link and a box (``swept``), and the local coordinates of a point of
    a link in the link's frame (``loc``: what the definition's "there are (u, v)" names)."""

    tag: str
    link: z3.FuncDeclRef
    swept: z3.FuncDeclRef
    loc: tuple[z3.FuncDeclRef, z3.FuncDeclRef]
    b: Vec
    l1: z3.ArithRef
    l2: z3.ArithRef
    r1: z3.ArithRef
    r2: z3.ArithRef
    rb1: z3.ArithRef
    re2: z3.ArithRef

    @classmethod
    def named(cls, tag: str) -> ArmModel:
        link = _LINK_L if tag == "L" else _LINK_R
        swept = _SWEPT_L if tag == "L" else _SWEPT_R
        loc = tuple(z3.Function(f"{tag}.loc{c}", z3.IntSort(), *[_R] * 4, _R) for c in "uv")
        l1, l2, r1, r2, rb1, re2 = z3.Reals(" ".join(f"{tag}.{n}" for n in (
            "l1", "l2", "r1", "r2", "Rb1", "Re2")))
        return cls(tag, link, swept, (loc[0], loc[1]), _v(f"{tag}.b"), l1, l2, r1, r2, rb1, re2)

    def holds(self, x: int, theta: Vec, p: Vec) -> z3.BoolRef:
        return self.link(x, theta[0], theta[1], p[0], p[1])

    def local(self, x: int, theta: Vec, p: Vec) -> Vec:
        args = (x, theta[0], theta[1], p[0], p[1])
        return (self.loc[0](*args), self.loc[1](*args))

    def frame_point(self, x: int, alpha: z3.ArithRef, phi: z3.ArithRef, uv: Vec) -> Vec:
        """docs/model.md §2: the point at local coordinates uv of link 1's frame (at the base,
        turned by alpha = theta1) or link 2's (at the elbow b + l1 e(alpha), turned by
        phi = theta1 + theta2)."""
        if x == 0:
            return _add(self.b, _rot(e(alpha), uv))
        return _point2(self.b, self.l1, alpha, phi, uv[0], uv[1])

    def point(self, x: int, theta: Vec, uv: Vec) -> Vec:
        """The point at local coordinates uv of link x at theta."""
        return self.frame_point(x, theta[0], theta[0] + theta[1], uv)

    def reach(self, x: int) -> Vec:
        """(R_base, R_elbow) as impl.link_reach gives them, in the proofs' names."""
        return (self.rb1, z3.RealVal(0)) if x == 0 else (self.l1 + self.re2, self.re2)

    def geometry(self) -> tuple[Hyp, ...]:
        """The arm's link geometry (docs/model.md §2; the loader's checks), both links."""
        return (
            (f"{self.tag}: links (docs/model.md §2): l1, l2 > 0, r1 = w1/2 > 0, r2 = w2/2 > 0",
             z3.And(self.l1 > 0, self.l2 > 0, self.r1 > 0, self.r2 > 0)),
            (f"{self.tag}: R_base of link 1 = sqrt((l1 + r1)^2 + r1^2) (named)",
             z3.And(self.rb1 >= 0, self.rb1 * self.rb1 == (self.l1 + self.r1) * (self.l1 + self.r1)
                    + self.r1 * self.r1)),
            (f"{self.tag}: R_elbow of link 2 = sqrt((l2 + r2)^2 + r2^2) (named)",
             _elbow_reach(self.l2, self.r2, self.re2)),
        )

    def link_definition(self, x: int) -> tuple[list[z3.ExprRef], z3.BoolRef]:
        """Definitional (docs/model.md §2): a point of link x at theta is the point of the
        link's rectangle at its local coordinates (u, v): -r <= u <= l + r, |v| <= r. Returns
        its bound names and its body."""
        pre = f"{self.tag}.d1.{x}!"
        t1, t2, p1, p2 = z3.Reals(f"{pre}t1 {pre}t2 {pre}p1 {pre}p2")
        theta, p = (t1, t2), (p1, p2)
        uv = self.local(x, theta, p)
        r, ell = (self.r1, self.l1) if x == 0 else (self.r2, self.l2)
        return [t1, t2, p1, p2], z3.Implies(
            self.holds(x, theta, p),
            z3.And(in_rect(uv, r, ell), _veq(p, self.point(x, theta, uv))))

    def margin(self, x: int, box: Box, anchor: Vec, g: Vec,
               margin: Callable[..., object] = sweep_margin) -> z3.ArithRef:
        """impl.sweep_margin for the box's lattice (a joint with one lattice point is not
        moving), read as Safety.region_soundness reads it."""
        moving = []
        for q in range(2):
            lo_i, hi_i = lattice_range(box[q][0], box[q][1], anchor[q], g[q])
            moving.append(z3.BoolVal(False) if (x == 0 and q == 1) else hi_i > lo_i)
        return impl_margin(x, g, self.reach(x), (moving[0], moving[1]), margin)

    def hull_definition(self, x: int, box: Box, anchor: Vec, g: Vec,
                        margin: Callable[..., object] = sweep_margin
                        ) -> tuple[list[z3.ExprRef], z3.BoolRef]:
        """Definitional (docs/model.md §4.2: the region is the convex hull of the link's
        rectangles grown by impl.sweep_margin at the lattice configurations of impl.lattice_range):
        a point q that is a convex combination of points of those grown rectangles is a member
        of the region. Stated for the corners the proof combines (four for link 2, two for link 1, whose
        lattice has the one point anchor2 in theta2); returns its bound names and its body."""
        n = 4 if x == 1 else 2
        pre = f"{self.tag}.d2.{x}!"
        lat = [lattice_range(box[q][0], box[q][1], anchor[q], g[q]) for q in range(2)]
        delta = self.margin(x, box, anchor, g, margin)
        r, ell = (self.r1, self.l1) if x == 0 else (self.r2, self.l2)
        bound: list[z3.ExprRef] = []
        conds: list[z3.BoolRef] = []
        pts: list[Vec] = []
        ws: list[z3.ArithRef] = []
        for c in range(n):
            i, j = z3.Int(f"{pre}i{c}"), z3.Int(f"{pre}j{c}")
            al, be, ph, w = z3.Reals(f"{pre}alpha{c} {pre}beta{c} {pre}phi{c} {pre}w{c}")
            uv = _v(f"{pre}uv{c}")
            bound += [i, j, al, be, ph, w, uv[0], uv[1]]
            conds += [lat[0][0] <= i, i <= lat[0][1], al == anchor[0] + z3.ToReal(i) * g[0],
                      in_rect(uv, r + delta, ell), w >= 0]
            if x == 1:
                conds += [lat[1][0] <= j, j <= lat[1][1], be == anchor[1] + z3.ToReal(j) * g[1],
                          ph == al + be]
            pts.append(self.frame_point(x, al, ph, uv))
            ws.append(w)
        q = _v(f"{pre}q")
        conds += [z3.Sum(ws) == 1, _veq(q, _weighted(ws, pts))]
        body = z3.Implies(z3.And(conds), member(_swept(self.swept, x, box, anchor, g), q))
        return bound + [q[0], q[1]], body


def region_statement(arm: ArmModel, x: int) -> tuple[list[z3.ExprRef], z3.BoolRef]:
    """Safety.region_statement's conclusion for link x of ``arm``, over its bound names: for
    every box, lattice anchor and spacing (0 < g_q <= 157/50), configuration theta in the box
    and point p, a point of link x at theta is a member of the region built for x, the box,
    the anchor and the spacing."""
    pre = f"{arm.tag}.rs{x}!"
    lo1, hi1, lo2, hi2, a1, a2, g1, g2, t1, t2, p1, p2 = z3.Reals(
        " ".join(pre + n for n in "lo1 hi1 lo2 hi2 A1 A2 g1 g2 t1 t2 p1 p2".split()))
    box, anchor, g, theta, p = ((lo1, hi1), (lo2, hi2)), (a1, a2), (g1, g2), (t1, t2), (p1, p2)
    body = z3.Implies(z3.And(in_box(theta, box), spacing_ok(g), arm.holds(x, theta, p)),
                      member(_swept(arm.swept, x, box, anchor, g), p))
    return [lo1, hi1, lo2, hi2, a1, a2, g1, g2, t1, t2, p1, p2], body


def region_statement_closed(arm: ArmModel) -> z3.BoolRef:
    """region_statement for both links of ``arm``, universally closed."""
    parts = []
    for x in LINKS:
        bound, body = region_statement(arm, x)
        parts.append(z3.ForAll(bound, body))
    return z3.And(parts)


#: The hypotheses of link{1,2}_in_region that the derivation discharges itself rather than
#: passes through as definitions of the lemma's named quantities: the link's geometry (the
#: arm's), theta in the box and the spacings (the statement's antecedent), (u, v) in the
#: rectangle (the link's definition).
_DERIVED = {
    0: ("link 1 (docs/model.md §2): l1 > 0, r = w/2 > 0", "R_base = sqrt((l1 + r)^2 + r^2)",
        "theta1 in the box", "lattice spacings 0 < g_q <= 3.14",
        "(u, v) a point of link 1's rectangle"),
    1: ("link 2 (docs/model.md §2): l1, l2 > 0, r = w/2 > 0",
        "R_elbow = sqrt((l2 + r)^2 + r^2), R_base = l1 + R_elbow", "theta in the box",
        "lattice spacings 0 < g_q <= 3.14", "(u, v) a point of link 2's rectangle"),
}


def region_statement_vc(arm: ArmModel, x: int, kit: Kit | None = None,
                        margin: Callable[..., object] = sweep_margin) -> VC:
    """Safety.region_statement for link x of ``arm``: region_statement's body at its bound
    names (so its universal closure), from the link's definition at (theta, p), the hull's
    definition at the corners link{x+1}_in_region exhibits, and that lemma (proved in
    Safety.region_soundness) instantiated by substitution at the arm's geometry, the box,
    theta and (u, v) = the point's local coordinates. ``margin`` is the region's (the tests'
    mutant); the lemma keeps the kit's."""
    kit = kit or region_kit()
    lem = kit[f"link{x + 1}_in_region"]
    bound, goal = region_statement(arm, x)
    lo1, hi1, lo2, hi2, a1, a2, g1, g2, t1, t2, p1, p2 = bound
    box, anchor, g, theta, p = ((lo1, hi1), (lo2, hi2)), (a1, a2), (g1, g2), (t1, t2), (p1, p2)
    uv = arm.local(x, theta, p)
    pre = "lk1" if x == 0 else "lk2"
    R = z3.Real
    if x == 0:
        pairs = [(R("lk1.l1"), arm.l1), (R("lk1.r"), arm.r1), (R("lk1.Rb"), arm.rb1),
                 (R("lk1.lo1"), lo1), (R("lk1.hi1"), hi1), (R("lk1.theta1"), t1),
                 (R("lk1.A1"), a1), (R("lk1.g1"), g1), (R("lk1.g2"), g2)]
    else:
        pairs = [(R("lk2.l1"), arm.l1), (R("lk2.l2"), arm.l2), (R("lk2.r"), arm.r2),
                 (R("lk2.Re"), arm.re2), (R("lk2.lo1"), lo1), (R("lk2.hi1"), hi1),
                 (R("lk2.theta1"), t1), (R("lk2.A1"), a1), (R("lk2.g1"), g1),
                 (R("lk2.lo2"), lo2), (R("lk2.hi2"), hi2), (R("lk2.theta2"), t2),
                 (R("lk2.A2"), a2), (R("lk2.g2"), g2)]
    pairs += [(R(f"{pre}.b.x"), arm.b[0]), (R(f"{pre}.b.y"), arm.b[1]),
              (R(f"{pre}.u"), uv[0]), (R(f"{pre}.v"), uv[1])]
    names = {n for n, _ in lem.hyps}
    missing = [n for n in _DERIVED[x] if n not in names]
    if missing:
        raise KeyError(f"{lem.vc.name} has no hypotheses {missing}: _DERIVED is out of date")
    def sub(f: z3.ExprRef) -> z3.ExprRef:
        return concrete(z3.substitute(f, *pairs))
    defs = [(f"{n} [{lem.vc.name}'s named quantity]", sub(h)) for n, h in lem.hyps
            if n not in _DERIVED[x] and not n.startswith(_CARRIED + (_PROVED,))]
    # The corners, weights and local coordinates link{x+1}_in_region's conclusion names.
    c1, G1 = R(f"{pre}.joint1.c"), R(f"{pre}.joint1.G")
    j1, st1 = z3.Int(f"{pre}.joint1.j"), z3.If(z3.Bool(f"{pre}.joint1.moving"), 1, 0)
    D = _v(f"{pre}.D")
    if x == 1:
        c2, G2 = R("lk2.joint2.c"), R("lk2.joint2.G")
        j2, st2 = z3.Int("lk2.joint2.j"), z3.If(z3.Bool("lk2.joint2.moving"), 1, 0)
        lam, mu, nu = z3.Reals("lk2.lam lk2.mu lk2.nu")
        alphas = (c1, c1, c1 + G1, c1 + G1)
        betas = (c2, c2 + G2, c2, c2 + G2)
        phis = (c1 + c2, (c1 + c2) + G2, (c1 + G1) + c2, ((c1 + G1) + c2) + G2)
        i_s = (j1, j1, j1 + st1, j1 + st1)
        j_s = (j2, j2 + st2, j2, j2 + st2)
        ws = ((1 - lam) * (1 - mu), (1 - lam) * mu, lam * (1 - nu), lam * nu)
    else:
        lam = R("lk1.lam")
        alphas = (c1, c1 + G1)
        betas = phis = (R("lk1.unused"),) * 2
        i_s, j_s = (j1, j1 + st1), (z3.IntVal(0),) * 2
        ws = (1 - lam, lam)
    uvs = [grown_coords(ph if x == 1 else a, *(sub(z) for z in (R(f"{pre}.u"), R(f"{pre}.v"))),
                        D) for a, ph in zip(alphas, phis)]
    hull_bound, hull = arm.hull_definition(x, box, anchor, g, margin)
    inst: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    for c in range(len(alphas)):
        vals = [i_s[c], j_s[c], alphas[c], betas[c], phis[c], ws[c], uvs[c][0], uvs[c][1]]
        inst += list(zip(hull_bound[8 * c: 8 * c + 8], vals))
    inst += list(zip(hull_bound[-2:], p))        # the combination is the point p itself
    key = f"{arm.tag}: the hull's definition at link {x + 1}'s corners (docs/model.md §4.2)"
    link_bound, link_def = arm.link_definition(x)
    hyps: list[Hyp] = [
        *arm.geometry(),
        (f"{arm.tag}: link {x + 1}'s definition (docs/model.md §2) at (theta, p)",
         z3.substitute(link_def, *zip(link_bound, [t1, t2, p1, p2]))),
        (key, concrete(z3.substitute(hull, *inst))),
    ]
    hyps += defs
    hyps += [(n, concrete(h)) for n, h in lem.use(pairs, f"{arm.tag}, link {x + 1}")]
    # The lemma's small arm at rest in a one-point box, for the vacuity check; its point (u, v)
    # becomes the local coordinates of p.
    wit = tuple((sub(c), v) for c, v in lem.vc.witness)
    return VC(f"region_statement_{arm.tag}_link{x + 1}", _dedupe(hyps), goal, key_premise=key,
              witness=wit, counter_witness=wit)


def rectangle_vc(x: int, rectangles: Callable[..., object] | None = None) -> VC:
    """The rectangle both definitions of region_statement use is impl's: impl.link_rectangles(arm,
    theta1, theta2, link x, grow) (or ``rectangles``, the tests' mutant), its module's own code
    run on the terms (numpy's cos and sin as Cos, Sin), for a symbolic arm, configuration and
    grow >= 0, has the corners of ArmModel's rectangle -r' <= u <= l + r', |v| <= r' (r' = w/2 +
    grow) in the link's frame, counter-clockwise from (-r', -r'): the link's definition (grow
    0) and the hull's (grow = sweep_margin) are the code's rectangle."""
    from types import SimpleNamespace

    import numpy as np

    from ..impl import link_rectangles
    from ._obl_tools import module_on_terms
    fn = rectangles or link_rectangles
    arm = ArmModel.named("rect")
    r = arm.r1 if x == 0 else arm.r2
    ell = arm.l1 if x == 0 else arm.l2
    t1, t2, grow = z3.Reals("rect.theta1 rect.theta2 rect.grow")
    # Lengths as object arrays and the width as a one-element one, so that numpy, not Z3,
    # broadcasts a term times an array (as read_tool's arm does).
    code = SimpleNamespace(base=arm.b, links=(np.asarray(arm.l1, dtype=object),
                                              np.asarray(arm.l2, dtype=object)),
                           width=np.asarray([2 * r], dtype=object), tool=None, z=None)
    got = np.asarray(module_on_terms(fn)[fn.__name__](code, t1, t2, x, grow=grow),
                     dtype=object).reshape(-1, 2)
    names = [_v(f"rect.C{i + 1}") for i in range(len(got))]
    key = (f"C = impl.link_rectangles(arm, theta1, theta2, link {x + 1}, grow), read on terms "
           "(its corners named C1..C4)")
    R = r + grow
    want = [arm.frame_point(x, t1, t1 + t2, (u, v))
            for u, v in ((-R, -R), (ell + R, -R), (ell + R, R), (-R, R))]
    hyps = (("the arm: l1, l2 > 0, r = w/2 > 0, grow >= 0",
             z3.And(arm.l1 > 0, arm.l2 > 0, r > 0, grow >= 0)),
            (key, z3.And([_veq(n, (z3.simplify(g[0]) if isinstance(g[0], z3.ExprRef) else g[0],
                                   z3.simplify(g[1]) if isinstance(g[1], z3.ExprRef) else g[1]))
                          for n, g in zip(names, got)])))
    goal = z3.And([_veq(w, n) for w, n in zip(want, names)]) if len(names) == 4 else \
        z3.BoolVal(False)
    return VC(f"rectangle_link{x + 1}", hyps, goal, key_premise=key)


def region_statement_query() -> Z3Query:
    kit = region_kit()
    return Z3Query(tuple(rectangle_vc(x) for x in LINKS)
                   + tuple(region_statement_vc(ArmModel.named(t), x, kit)
                           for t in ("L", "R") for x in LINKS))


#: How region_instances names the tool's statement (its derivation: Safety.tool_region's
#: tool_statement_L/R).
TOOL_STATEMENT = "Safety.tool_region's tool_statement"


def tool_statement_closed(tag: str) -> z3.BoolRef:
    """The tool's region statement for arm ``tag``, universally closed: region_statement's form
    for part 3 (a point of the tool at a configuration of a box is a member of the region built
    for the tool and the box), derived in Safety.tool_region (tool_statement_L/R)."""
    bound, body = region_statement(ArmModel.named(tag), TOOL)
    return z3.ForAll(bound, body)


def region_instance_vc(variant: str) -> VC:
    """The compositions' (c) hypotheses are instances of Safety.region_statement (proved for
    both arms' links from Safety.region_soundness's lemmas and the definitions of a link and a
    region), once the regions are read as BuiltDR builds them: layer k's (k < N) is the region
    of its box on the lattice anchored at theta_L(k dt) with spacing omega dt; the rest layer's
    of the rest box (anchored at the goal for tight, else layer N-1's); a cell's of its box,
    anchored at the cell's angles with spacing h. A (c) hypothesis stronger than the statement
    (a box condition dropped, say) is refuted here."""
    at = _At.named()
    region_l, region_rest, region_r = _regions(variant)
    P, k, here = at.P, at.k, at.here
    arm_l, arm_r = ArmModel.named("L"), ArmModel.named("R")
    g_l = (P.omega[0] * P.dt, P.omega[1] * P.dt)
    rest_anchor = P.goal if Variant(variant).rest_at_goal else P.theta(
        (z3.ToReal(at.d.N) - 1) * P.dt)
    key = "Safety.region_statement for the principal's links"
    hyps: list[Hyp] = [
        *arm_l.geometry(), *arm_r.geometry(),
        (key, region_statement_closed(arm_l)),
        ("Safety.region_statement for the subordinate's links", region_statement_closed(arm_r)),
        (TOOL_STATEMENT + " for the principal's tool", tool_statement_closed("L")),
        (TOOL_STATEMENT + " for the subordinate's tool", tool_statement_closed("R")),
        ("the loader's spacing checks: 0 < omega_q dt <= 157/50, 0 < h_q <= 157/50",
         z3.And(spacing_ok(g_l), spacing_ok(at.S.h))),
        ("layer k's regions are the regions built for its box, anchored at theta_L(k dt), "
         "spacing omega dt (k < N)",
         z3.Implies(z3.And(0 <= k, k < at.d.N), z3.And([
             region_l(k, x) == _swept(_SWEPT_L, x, P.box(variant, z3.ToReal(k)),
                                      P.theta(z3.ToReal(k) * P.dt), g_l)
             for x in PARTS]))),
        ("the rest layer's regions are the regions built for the rest box",
         z3.And([region_rest(x) == _swept(_SWEPT_L, x, P.rest_box(variant), rest_anchor, g_l)
                 for x in PARTS])),
        ("a cell's regions are the regions built for its box, anchored at its angles, spacing h",
         z3.Implies(in_grid(at.d, here), z3.And([
             region_r(here[0], here[1], x) == _swept(_SWEPT_R, x, at.S.box(here),
                                                     at.S.angle(here), at.S.h)
             for x in PARTS]))),
    ]
    goal = z3.And([h for _, h in region_hypotheses(variant, at)])
    one = z3.IntVal(1)
    pins = ((at.d.N, one), (at.d.m, one), (at.d.n, one))
    # Without the key, the counter-model at step 0 of unit steps (Z3 took 21 s to find one for
    # modified with the one-cell pins alone, 0.4 s with these).
    steps = ((k, z3.IntVal(0)), (P.dt, z3.RealVal(1)))
    return VC(f"region_instances_{variant}", tuple(hyps), goal, key_premise=key, witness=pins,
              counter_witness=pins + steps)


#: A rational below pi (pi = 3.14159265...): what A3's facts on [0, pi] need of G_MAX.
PI_BELOW = z3.Q(314159, 100000)


def spacing_bound_vc(bound: z3.ArithRef | None = None) -> VC:
    """The loader's spacing bound (spec.MAX_SPACING, read: G_MAX) lies below pi, so A3's facts,
    stated on [0, G_MAX] where they hold on [0, pi] (cos non-increasing, sin >= 0; cos >= 0 up
    to G_MAX / 2 < pi / 2), hold there. ``bound`` replaces G_MAX (the tests' mutant)."""
    pi = z3.Real("pi")
    key = "pi > 314159/100000"
    g = G_MAX if bound is None else bound
    return VC("spacing_below_pi", ((key, pi > PI_BELOW),), g < pi, key_premise=key,
              witness=((pi, z3.Q(314159265, 100000000)),), counter_witness=())


def pair_apart_lemma() -> Lemma:
    """(d) at one pair of regions, as the compositions use it at each pair BuiltDR tests: with
    eps = spec.EPS, err = spec.DISTANCE_ERROR_M, A12 at the pair and what a positive distance
    means, a pair BuiltDR frees (float distance > eps) has no common point."""
    A, B = z3.Consts("pa.A pa.B", REGION)
    eps, err = z3.Reals("eps err")
    p = _v("pa.p")
    key = "BuiltDR frees the pair: fdist(A, B) > eps"
    hyps = ((EPS_HYP, eps == EPS_Q), (ERR_HYP, err == ERR_Q),
            ("A12: |fdist(A, B) - dist(A, B)| <= err", rounding(A, B, err)),
            ("the distance of compact regions", distance_meaning(A, B)),
            (key, float_free(A, B, eps)))
    return lemma("pair_apart", hyps, z3.Not(z3.And(member(A, p), member(B, p))), key,
                 names=dict(A=A, B=B, p=p))


def composition_vc(variant: str, *, a: tuple[Lemma, Lemma] | None = None,
                   b: tuple[Lemma, Lemma] | None = None) -> VC:
    """(e) for ``variant``; the lemmas may be replaced (the tests' mutants).

    Every hypothesis is a premise the conclusion needs: ``cfmpa prove`` drops each in turn and
    requires the composition without it not to be proved (proofs/_controls.py). A fact used at
    several points (a region's soundness for both links, the rounding bound at the eight pairs
    of regions) is one hypothesis, the conjunction of its instances."""
    motion, rest = a or principal_lemmas(variant)
    move, _ = b or subordinate_lemmas()
    step = _step_lemma()
    P = Principal.named()
    S = Subordinate.named()
    d = Z3Dims.named()
    ints = z3.IntSort()
    DR = z3.Array("P", ints, ints, ints, ints)
    start, goal = (z3.Int("start.i"), z3.Int("start.j")), (z3.Int("goal.i"), z3.Int("goal.j"))
    L = z3_path("L")
    t, eps, err = z3.Real("t"), z3.Real("eps"), z3.Real("err")
    k = z3.Int("kk")
    p = _v("p")
    region_l, region_rest, region_r = _regions(variant)

    hl, hr = Heights.named("L"), Heights.named("R")
    kept = {(x, y): pair_kept(hl, hr, x, y) for x in PARTS for y in PARTS}

    def all_free(left: Callable[[int], z3.ExprRef], i: z3.ArithRef, j: z3.ArithRef) -> z3.BoolRef:
        return z3.And([z3.Implies(kept[x, y], float_free(left(x), region_r(i, j, y), eps))
                       for x in PARTS for y in PARTS])

    post = blocked_exact(
        DR, d, motion=lambda kk, i, j: z3.Not(all_free(lambda x: region_l(kk, x), i, j)),
        rest=lambda _, i, j: z3.Not(all_free(region_rest, i, j)))
    here, nxt = position(L, k), position(L, k + 1)
    theta_l = P.theta(t)
    theta_r = S.theta(here, nxt, k, t, P.dt)
    pairs = [(A, region_r(here[0], here[1], y)) for x in PARTS
             for A in (region_l(k, x), region_rest(x)) for y in PARTS]
    key = ("Theorem 1/3's postcondition: P[k,i,j] = 0 iff every pair of part regions the height "
           "rule keeps (spec.pairs_to_test) has a float distance > eps")
    hyps: list[Hyp] = [
        *P.basics(), P.n_def(), ("h_q > 0", z3.And(S.h[0] > 0, S.h[1] > 0)),
        ("is_path L (fixed, docs/model.md §5)", is_path_fixed(DR, d, start, goal, L)),
        (key, post),
        ("t >= 0", t >= 0),
        ("k = floor(t / dt), the step at t (named)", k == z3.ToInt(t / P.dt)),
        (EPS_HYP, eps == EPS_Q), (ERR_HYP, err == ERR_Q),
        ("A12 at the eighteen pairs of regions (layer k and rest, parts x parts): "
         "|fdist - dist| <= err", z3.And([rounding(A, B, err) for A, B in pairs])),
        ("the distance of compact regions at the eighteen pairs: dist > 0 -> no common point",
         z3.And([distance_meaning(A, B) for A, B in pairs])),
    ]
    hyps += step.at("t", k=k, N=d.N, t=t)
    pa = pair_apart_lemma()
    for n, (A, B) in enumerate(pairs):
        hyps += pa.at(f"pair {n + 1} of regions", A=A, B=B, p=p)
    hyps += motion.at("the step k (a)", k=k, t=t)
    hyps += rest.at("t (a)", t=t)
    hyps += move.at("the step k (b)", c=here, c2=nxt, k=k, t=t)
    at = _At.named()
    hyps += region_hypotheses(variant, at)
    hyps += [("the prisms' outlines (docs/model.md §2): a point of part x's prism lies over a "
              "point of part x; an arm without a tool has no part 3",
              z3.And(hl.outline(theta_l, p, at.z), hr.outline(theta_r, p, at.z))),
             (HEIGHT_HYP, height_hypothesis(at))]
    target = z3.And([z3.Not(z3.And(hl.solid(x, theta_l, p, at.z), hr.solid(y, theta_r, p, at.z)))
                     for x in PARTS for y in PARTS])
    one, zero = z3.IntVal(1), z3.IntVal(0)
    # One layer, a one-cell grid, a one-cell path: where Z3 finds the models the vacuity check
    # and the negative controls ask for.
    pins = ((d.N, one), (d.m, one), (d.n, one), (L.length, one), (start[0], zero),
            (start[1], zero), (goal[0], zero), (goal[1], zero))
    # The vacuity check's model also at rest, at t = 0 (finding one for the regions' points is
    # otherwise left to Z3's model search, which one seed of three missed in 20 s).
    rz, r1 = z3.RealVal(0), z3.RealVal(1)
    at_rest = ((t, rz), (k, zero), (P.dt, r1), (P.omega[0], r1), (P.omega[1], r1),
               (P.start[0], rz), (P.start[1], rz), (P.goal[0], rz), (P.goal[1], rz))
    return VC(f"composition_{variant}", _dedupe(hyps), target, key_premise=key,
              witness=pins + at_rest, counter_witness=pins)


# --- the obligations ---------------------------------------------------------------------------

_RULES = {
    "original": ("[a - omega_q dt, a + omega_q dt], a = theta_L(k dt) (Algorithm 1)",
                 "layer N-1's box"),
    "modified": ("from a = theta_L(k dt) to a + s_q omega_q dt, s_q = +1 if goal_q > start_q "
                 "else -1 (Section IV.A)", "layer N-1's box"),
    "tight": ("from theta_L(k dt) to theta_L((k+1) dt)", "the goal, a one-point box"),
}


def _principal_query(variant: str) -> Z3Query:
    steps = principal_steps(Principal.named())
    motion, rest = principal_lemmas(variant)
    return Z3Query(tuple(L.vc for L in steps.values()) + (motion.vc, rest.vc))


def _subordinate_query() -> Z3Query:
    move, on_path = subordinate_lemmas()
    return Z3Query((move.vc, on_path.vc))


def _separation_query() -> Z3Query:
    return Z3Query(tuple(L.vc for L in separation_lemmas()))


def _composition_query(variant: str) -> Z3Query:
    return Z3Query((_step_lemma().vc, pair_apart_lemma().vc, spacing_bound_vc(),
                    region_instance_vc(variant), height_instance_vc(), composition_vc(variant)))


def safety_obligations() -> list[Obligation]:
    """Safety.*: (a) per variant, (b), (c), (d), (e) per variant (docs/model.md §10)."""
    P, Z = Verdict.PROVED, Method.Z3
    out = []
    for v in VARIANTS:
        rule, rest = _RULES[v]
        out.append(Obligation(
            f"Safety.{v}.principal_in_layer_box", GROUP, "docs/model.md §2, §4.1, §10 (a)",
            "For symbolic start, goal, omega_q > 0 and dt > 0 (both joints), with Tf = max_q "
            "|goal_q - start_q| / omega_q and theta_L(t) = start + (goal - start) min(max(t / Tf, "
            "0), 1) (1 when Tf = 0, spec.left_angles): (motion) for every integer k >= 0 and t in "
            f"[k dt, (k+1) dt], theta_L(t) lies in layer k's box, {rule}; (rest) with N = "
            "max(1, ceil(Tf / dt)) (spec.exact_n), for every t >= N dt it lies in the rest "
            f"layer's box, {rest}. Quantifier-free nonlinear real arithmetic (division, min, max, "
            "ceil), split so that cvc5 decides every VC as Z3 does: frac_step (the PTP fraction "
            "advances by at most dt / Tf over a window of dt), travel (|goal_q - start_q| <= "
            "omega_q Tf), step1/step2 (a joint's displacement over such an advance is within "
            "omega_q dt, with the travel's sign), n_covers (N dt >= Tf) and at_rest (the "
            "fraction is 1 from N dt on), used by substitution in motion and rest; the box "
            "rule is docs/model.md §4.1's, and the tests check it against "
            "spec.left_box on every layer of the bundled scenarios.",
            Z, P, lambda v=v: _principal_query(v),
            summary=("The principal arm's straight joint-space motion stays, within each time "
                     "step, inside the box of angles that step's layer is built for, and inside "
                     f"the rest layer's box once it has stopped ({v} variant).")))
    out.append(Obligation(
        "Safety.subordinate_in_cell_box", GROUP, "docs/model.md §2, §4.1, §5, §10 (b)",
        "(neighbour_move) For cells c, c' with |c'_q - c_q| <= 1, grid angles lo_q + i h_q (h_q > "
        "0) and t in [k dt, (k+1) dt], the subordinate's linear move theta_R(t) = angle(c) + ((t - "
        "k dt) / dt)(angle(c') - angle(c)) lies in c's box [t_i - h1, t_i + h1] x [t_j - h2, t_j "
        "+ h2] (spec.right_box) over the whole step. (on_path) Under the fixed is_path, at every "
        "step k >= 0 the cell held (position(L, k)) is in the grid and the cell held at k + 1 is "
        "a neighbour of it or itself; once the list has ended (k + 1 >= LENGTH(L)) both are the "
        "goal: the subordinate is at rest there.", Z, P, _subordinate_query,
        summary=("The subordinate arm, moving straight from cell to neighbouring cell each time "
                 "step, stays inside the box of angles of the cell it holds, and rests at its goal "
                 "once the path ends.")))
    out.append(Obligation(
        "Safety.region_soundness", GROUP, "docs/model.md §2, §4.2, §10 (c)",
        "A point (u, v) of link 1's or link 2's rectangle (docs/model.md §2: half-width r = w/2, "
        "extended by r past both joints; R_base, R_elbow the §2 reach) at any configuration "
        "theta of a box [lo1, hi1] x [lo2, hi2] lies in the region impl.swept_region builds for "
        "the box: the lattice A_q + i g_q (0 < g_q <= 3.14) with the indices of "
        "impl.lattice_range, read by running lattice_range itself on the symbols "
        "(floor((lo - A)/g + SNAP), ceil((hi - A)/g - SNAP)), the link's rectangle at every "
        "lattice configuration grown by Delta = impl.sweep_margin, and their convex hull. The "
        "point is exhibited as a convex combination of points of the grown rectangles at the "
        "corners of the lattice cell that holds theta clamped onto the lattice's span (four "
        "corners for link 2, two for link 1, which does not depend on theta2). The margin is "
        "derived, not assumed: clamping theta_q "
        "by at most SNAP g_q moves the point by at most SNAP g_q R_q (chord, from cos x >= 1 - "
        "x^2/2), and Margin.arc_chord, re-proved here as the first VC (from arc_weight, arc_dist "
        "and arc_gap, where its constant is paid), is instantiated by "
        "substitution at every arc (about the base, and about the elbow at both ends), at (r, "
        "G, e(G/2), e(psi)), and moved from the origin to the arc's pivot and position by the "
        "rigid motion R(mid) (rigid_id, rot_norm, rot_scale, scale_norm): its bound r G^2/8 at "
        "R, G the cell's step for a joint with more than one lattice point, else 0. "
        "margin_covers_link1/2 show that impl.sweep_margin, read by calling it on symbolic "
        "spacings (its probe arm's reach replaced by symbols; the reading checked against its "
        "floats on sample arms), is at least the derived margin: a wrong constant fails the "
        "obligation (1/16 in the lemma: arc_gap; 1/4 there, or 1/16 in sweep_margin, "
        "margin_covers). sin and cos are the uninterpreted Cos, Sin with "
        "the ledger's facts (A3) at the points named. Split into lemmas Z3 and cvc5 each decide "
        "quickly: small "
        "ones on the polynomials, and compositions (chord, arc_in_place, reach_link2, grow, "
        "triangle, scale_bound, combine1, combine2_norm, combine2_weights, transport, "
        "transport_chord, shift_eq, sum_subst, link1_in_region, link2_in_region; the lattice "
        "through lattice_span and lattice_snap) valid for "
        "every function sq, dt standing for |v|^2 and the dot product, each using the others "
        "by substitution with the facts they rest on carried along; intermediate quantities "
        "(lattice indices, chord weights, points, the displacement D) are named by their "
        "definitions. For both arms: the subordinate's regions are built at t_i = 0 and turned "
        "by t_i, the same construction up to rounding (ledger A2).",
        Z, P, region_query,
        summary=("Every point of a link, at any joint angles inside a box, lies inside the swept "
                 "region the planner builds for that box: the margin it adds covers the motion "
                 "between the grid's sample angles.")))
    out.append(Obligation(
        "Safety.region_statement", GROUP, "docs/model.md §2, §4.2, §10 (c')",
        "For each arm (the principal L, the subordinate R) and each link x: for every box "
        "[lo1, hi1] x [lo2, hi2], lattice anchor A and spacing g (0 < g_q <= 157/50), "
        "configuration theta in the box and point p, if p is a point of link x at theta "
        "(linkL/linkR) then p is a member of the region built for x, the box, A and g "
        "(sweptL/sweptR). Derived, not named: from (1) the link's definition (docs/model.md §2: "
        "p is the point of the link's rectangle, half-width r = w/2 extended by r past both "
        "joints, at its local coordinates, a function of theta and p), (2) the region's "
        "definition (§4.2: a convex combination of points of the link's rectangles grown by "
        "impl.sweep_margin, read on the symbols, at lattice configurations whose indices "
        "impl.lattice_range gives, run on the symbols, is a member of the region; stated at "
        "the corners the proof combines), and (3) Safety.region_soundness's "
        "link1_in_region / link2_in_region, instantiated by substitution at the arm's "
        "geometry, the box, theta and the point's local coordinates, with the lemma's named "
        "quantities (lattice indices, chord weights, points, the displacement) defined as it "
        "defines them. The arm's geometry (l1, l2, r1, r2 > 0, R_base and R_elbow as square "
        "roots) is a premise. Both definitions are definitional (what linkL and the region "
        "mean); rectangle_link1/2 prove the rectangle both use is impl's: impl.link_rectangles, "
        "run on terms for a symbolic arm, configuration and grow >= 0, has its corners (a "
        "rectangle not extended past its joint is refuted); tests check (2)'s generating "
        "points against impl.swept_points and (1)'s rectangle against the link rectangles impl "
        "computes on floats. The compositions' "
        "region_instances VC takes this statement, universally closed, as its premise.",
        Z, P, region_statement_query,
        summary=("Hence, by what a link and a swept region are (a rectangle of the arm's geometry; "
                 "the hull of the grown rectangles at the sample angles), every point of either "
                 "arm's links at angles in a box is in that box's region.")))
    out.append(Obligation(
        "Safety.separation", GROUP, "docs/model.md §4.3, §10 (d)",
        "What eps buys. (eps_margin) BuiltDR frees a pair of regions when the distance it "
        "computes in doubles (or a lower bound of it: a box gap, a separating-axis gap) exceeds "
        "eps = spec.EPS = 1e-9 m; with that float value within err = spec.DISTANCE_ERROR_M "
        "(64 rounding units per metre of coordinate, for coordinates up to 4000 m: about "
        "2.8e-11 m; ledger A12, checked against exact rational arithmetic on random polygons) of "
        "the exact value, the exact distance is then > 0. Both constants are read from the code; "
        "any eps below err is refuted. (no_common_point) Regions at a positive distance hold "
        "links that share no point (the distance of compact sets is attained; definitional). "
        "Regions and links are opaque.",
        Z, P, _separation_query,
        summary=("A pair of regions the planner frees, its rounded distance above 1e-9 m, is truly "
                 "apart, since rounding errs by under 3e-11 m; links in regions apart share no "
                 "point.")))
    for v in VARIANTS:
        rest = ("the principal at rest at its goal" if v == "tight" else "layer N-1's region")
        out.append(Obligation(
            f"Safety.{v}.composition", GROUP, "docs/model.md §5, §7.2, §10 (e)",
            f"For the {v} variant: if D_R meets Theorem 1/3's postcondition with the "
            "intersection test read as distance (P[k,i,j] = 0 iff every pair of a principal part "
            f"region of layer k, the rest layer from N on ({rest}), and a subordinate part region "
            "of cell (i, j) that spec.pairs_to_test keeps -- both parts present, their height "
            "intervals overlapping by spec.heights_overlap run on the terms -- is more than eps "
            "apart) and L is a path under the fixed is_path, then at every instant t >= 0 no "
            "part (link 1, link 2, the tool; each the prism of its outline over its height "
            "interval) of the principal at theta_L(t) shares a point of 3-D space with a part "
            "of the subordinate at theta_R(t), the linear move from the cell held "
            "at step k to the one held at k + 1, k = floor(t / dt) (time_step: k dt <= t <= "
            "(k+1) dt, and t >= N dt once k >= N). Composed by substitution from "
            f"Safety.{v}.principal_in_layer_box (motion for k < N, rest from N dt on), "
            "Safety.subordinate_in_cell_box (neighbour_move; the fixed is_path gives the "
            "cells) and the time step; the free test is BuiltDR's own (float distance > eps), "
            "carried to the exact distance by Safety.separation's premises (eps, err, A12 at the "
            "eighteen pairs of regions of layer k and of the rest layer, what a positive distance "
            "means), used through pair_apart ((d) at one pair). The pairs the height rule drops: "
            "the hypothesis that they share no point, which height_instances derives from the "
            "prisms' definition (Safety.height_rule at the parts); spacing_below_pi: the "
            "loader's spacing bound (spec.MAX_SPACING, read) is below pi, where A3's facts "
            "hold. Tf and N are spec.exact_tf and spec.exact_n run on the terms. The regions' "
            "soundness enters as hypotheses at theta_L(t), theta_R(t) and "
            "the point (a link at a configuration of a region's box lies in the region); the VC "
            "region_instances derives each from Safety.region_statement (proved from "
            "Safety.region_soundness's lemmas and the definitions of a link and a region; here "
            "its universal closure, the same term), the loader's spacing checks and the regions "
            "read as BuiltDR builds them (layer k's: its box on the lattice anchored at "
            "theta_L(k dt), spacing omega dt; the rest layer's: the rest box, anchored at the "
            "goal for tight, else layer N-1's; a cell's: its box, anchored at its angles, "
            "spacing h), so a hypothesis stronger than the statement fails; the tool's three "
            "region hypotheses, from Safety.tool_region's tool_statement. Every "
            "hypothesis that is not a proved lemma's instance is needed: cfmpa prove's negative "
            "controls drop each and require the composition without it not proved.",
            Z, P, lambda v=v: _composition_query(v),
            summary=(f"The safety theorem ({v} variant): if D_R is as Theorems 1/3 say and the "
                     "path is valid, the two arms share no point at any instant of the executed "
                     "motion, in continuous time, not only at the grid's instants.")))
    return out
