"""The end-to-end safety theorem (docs/model.md §10): the ``Safety.*`` obligations.

For each variant, a path valid under the fixed is_path over a D_R that meets Theorem 1/3's
postcondition never lets the arms touch, at any instant t >= 0 of the executed motion (the
principal's PTP motion, the subordinate linear in joint space from cell to cell, one cell per
dt, then at rest). The parts, each an obligation, each (but (e)) in its own module:
_obl_safety_principal (a), _obl_safety_subordinate (b), _obl_safety_region (c),
_obl_safety_separation (d); this module holds the region statement, the heights and (e).

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

import functools
from collections.abc import Callable
from dataclasses import dataclass

import z3

from ..impl import lattice_range, sweep_margin
from ..spec import (
    Variant,
)
from ..spec.z3defs import (
    REGION,
    Z3Dims,
    blocked_exact,
    in_grid,
    is_path_fixed,
    member,
    position,
    z3_path,
)
from ._lemmas import CARRIED as _CARRIED
from ._lemmas import PROVED as _PROVED
from ._lemmas import Lemma, Substitution, lemma
from ._lemmas import dedupe as _dedupe
from ._obl_safety_principal import Principal, in_box, principal_lemmas, principal_steps, step_window
from ._obl_safety_region import (
    Kit,
    _elbow_reach,
    _point2,
    _weighted,
    grown_coords,
    impl_margin,
    in_rect,
    region_kit,
    region_query,
)
from ._obl_safety_separation import (
    _LINK_L,
    _LINK_R,
    EPS_HYP,
    EPS_Q,
    ERR_HYP,
    ERR_Q,
    distance_meaning,
    float_free,
    link_l,
    link_r,
    rounding,
    separation_lemmas,
)
from ._obl_safety_subordinate import Subordinate, subordinate_lemmas
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._z3vec import (
    G_MAX,
    Hyp,
    Vec,
    concrete,
    e,
)
from ._z3vec import add as _add
from ._z3vec import rot as _rot
from ._z3vec import vec as _v
from ._z3vec import veq as _veq

__all__ = ["VARIANTS", "safety_obligations"]

GROUP = "End-to-end safety (docs/model.md §10)"

VARIANTS = tuple(v.value for v in Variant)


_R = z3.RealSort()

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
    if Variant(variant).rest_at_goal:
        region_rest = z3.Function(f"regionRest_{variant}", ints, REGION)

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
    from ._onterms import as_bool as _bool
    from ._onterms import run_on_terms
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
        " ".join(pre + n for n in ("lo1", "hi1", "lo2", "hi2", "A1", "A2", "g1", "g2", "t1", "t2",
                                   "p1", "p2")))
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
    at_pairs = Substitution(pairs)

    def sub(f: z3.ExprRef) -> z3.ExprRef:
        return concrete(at_pairs(f))
    defs = [(f"{n} [{lem.vc.name}'s named quantity]", sub(h)) for n, h in lem.hyps
            if n not in _DERIVED[x] and not n.startswith(_CARRIED + (_PROVED,))]
    # The corners, weights and local coordinates link{x+1}_in_region's conclusion names.
    c1, G1 = R(f"{pre}.joint1.c"), R(f"{pre}.joint1.G")
    j1, st1 = z3.Int(f"{pre}.joint1.j"), z3.If(z3.Bool(f"{pre}.joint1.moving"), 1, 0)
    D = _v(f"{pre}.D")
    # Per corner of the cell: 4 for link 2, 2 for link 1.
    alphas: tuple[z3.ArithRef, ...]
    betas: tuple[z3.ArithRef, ...]
    phis: tuple[z3.ArithRef, ...]
    i_s: tuple[z3.ArithRef, ...]
    j_s: tuple[z3.ArithRef, ...]
    ws: tuple[z3.ArithRef, ...]
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
    uvs = [grown_coords(ph if x == 1 else a, sub(R(f"{pre}.u")), sub(R(f"{pre}.v")), D)
           for a, ph in zip(alphas, phis)]
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
    from ._onterms import module_on_terms
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

#: Each variant's box rule and rest layer in words, as its rule states them (docs/model.md §4.1).
_RULES = {v.value: (v.rule.words, v.rule.rest_words) for v in Variant}


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
            Z, P, functools.partial(_principal_query, v),
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
        rest = ("the principal at rest at its goal" if Variant(v).rest_at_goal
                else "layer N-1's region")
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
            Z, P, functools.partial(_composition_query, v),
            summary=(f"The safety theorem ({v} variant): if D_R is as Theorems 1/3 say and the "
                     "path is valid, the two arms share no point at any instant of the executed "
                     "motion, in continuous time, not only at the grid's instants.")))
    return out
