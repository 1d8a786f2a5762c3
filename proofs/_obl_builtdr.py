"""Theorem 1 and Theorem 3: BuiltDR's loop nest in the while-language, proved by WP and Z3.

The program mirrors ``cfmpa.impl.build_dr``: compute the left region of every layer, the right
region of every cell, then P[k, i, j] = (Inter(SL[k], SR[i, j]) -> 1 | 0) for every cell of
every layer, then the rest layer. Regions are values of an uninterpreted sort and the
intersection test an uninterpreted predicate, so the proof holds for any region function: the
original and the modified algorithm differ only in which one (``regionL_original`` vs
``regionL_modified``), and ``tight`` also in its rest layer (the principal at rest at its goal).
"""

from __future__ import annotations

from dataclasses import dataclass

import z3

from ..spec.z3defs import REGION, Z3Dims, blocked_exact, inter
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._while import Cmd, For, If, Seq, Store, verification_conditions

__all__ = ["BuiltDRModel", "builtdr_model", "builtdr_obligations"]

GROUP = "BuiltDR (Theorems 1, 3)"


@dataclass(frozen=True)
class BuiltDRModel:
    """The program, its pre- and postcondition, and the names it uses."""

    program: Cmd
    pre: z3.BoolRef
    post: z3.BoolRef
    dims: Z3Dims
    P: z3.ArrayRef


def builtdr_model(variant: str, *, bug: str | None = None) -> BuiltDRModel:
    """BuiltDR for ``variant`` (original, modified, tight). ``bug`` plants a known defect for
    the negative tests: ``inner_bound`` (j runs to n - 1), ``store_value`` (always stores 0),
    ``weak_invariant`` (the inner invariant forgets the finished layers), ``rest_layer``
    (the rest layer reads layer 0)."""
    d = Z3Dims.named()
    N, m, n = d.N, d.m, d.n
    ints = z3.IntSort()
    k, i, j = z3.Ints("k i j")
    P = z3.Array("P", ints, ints, ints, ints)
    SL = z3.Array("SL", ints, REGION)
    SR = z3.Array("SR", ints, ints, REGION)
    regionL = z3.Function(f"regionL_{variant}", ints, REGION)
    regionR = z3.Function("regionR", ints, ints, REGION)
    if variant == "tight":
        rest_region: z3.ExprRef = z3.Const("regionRest_tight", REGION)
    else:
        # The paper's rest layer: the last motion layer's region.
        rest_region = regionL(N - 1)

    def spec_motion(kk: z3.ArithRef, ii: z3.ArithRef, jj: z3.ArithRef) -> z3.BoolRef:
        return inter(regionL(kk), regionR(ii, jj))

    def spec_rest(_: z3.ArithRef, ii: z3.ArithRef, jj: z3.ArithRef) -> z3.BoolRef:
        return inter(rest_region, regionR(ii, jj))

    q1, q2, q3 = z3.Ints("q1 q2 q3")

    def sl_done(upto: z3.ArithRef) -> z3.BoolRef:
        return z3.ForAll([q1], z3.Implies(z3.And(0 <= q1, q1 < upto), SL[q1] == regionL(q1)))

    def sr_done(rows: z3.ArithRef, cols: z3.ArithRef | None = None,
                row: z3.ArithRef | None = None) -> z3.BoolRef:
        full = z3.ForAll([q1, q2], z3.Implies(z3.And(0 <= q1, q1 < rows, 0 <= q2, q2 < n),
                                              SR[q1, q2] == regionR(q1, q2)))
        if cols is None:
            return full
        part = z3.ForAll([q2], z3.Implies(z3.And(0 <= q2, q2 < cols),
                                          SR[row, q2] == regionR(row, q2)))
        return z3.And(full, part)

    def layers_done(upto: z3.ArithRef) -> z3.BoolRef:
        return z3.ForAll([q1, q2, q3], z3.Implies(
            z3.And(0 <= q1, q1 < upto, 0 <= q2, q2 < m, 0 <= q3, q3 < n),
            P[q1, q2, q3] == z3.If(spec_motion(q1, q2, q3), 1, 0)))

    def rows_done(layer: z3.ArithRef, rows: z3.ArithRef, spec: object) -> z3.BoolRef:
        return z3.ForAll([q2, q3], z3.Implies(z3.And(0 <= q2, q2 < rows, 0 <= q3, q3 < n),
                                              P[layer, q2, q3] == z3.If(spec(layer, q2, q3), 1, 0)))

    def cols_done(layer: z3.ArithRef, row: z3.ArithRef, cols: z3.ArithRef,
                  spec: object) -> z3.BoolRef:
        return z3.ForAll([q3], z3.Implies(z3.And(0 <= q3, q3 < cols),
                                          P[layer, row, q3] == z3.If(spec(layer, row, q3), 1, 0)))

    sizes = d.sane()
    ctx = z3.And(sizes, sl_done(N), sr_done(m))
    j_hi = n - 1 if bug == "inner_bound" else n
    one = z3.IntVal(0) if bug == "store_value" else z3.IntVal(1)
    rest_read = regionL(0) if (bug == "rest_layer" and variant != "tight") else None

    def mark(layer: z3.ArithRef, region: z3.ExprRef) -> Cmd:
        return If(inter(region, SR[i, j]), Store(P, (layer, i, j), one),
                  Store(P, (layer, i, j), z3.IntVal(0)))

    inner_layers = z3.BoolVal(True) if bug == "weak_invariant" else layers_done(k)
    program = Seq((
        # Phase A: the principal's region at every layer.
        For("A.k", k, z3.IntVal(0), N, z3.And(sizes, sl_done(k)),
            Store(SL, (k,), regionL(k))),
        # Phase B: the subordinate's region at every cell.
        For("B.i", i, z3.IntVal(0), m, z3.And(sizes, sl_done(N), sr_done(i)),
            For("B.j", j, z3.IntVal(0), n,
                z3.And(sizes, 0 <= i, i < m, sl_done(N), sr_done(i, j, i)),
                Store(SR, (i, j), regionR(i, j)))),
        # Phase C: the motion layers.
        For("C.k", k, z3.IntVal(0), N, z3.And(ctx, layers_done(k)),
            For("C.i", i, z3.IntVal(0), m,
                z3.And(ctx, 0 <= k, k < N, layers_done(k), rows_done(k, i, spec_motion)),
                For("C.j", j, z3.IntVal(0), j_hi,
                    z3.And(ctx, 0 <= k, k < N, 0 <= i, i < m, inner_layers,
                           rows_done(k, i, spec_motion), cols_done(k, i, j, spec_motion)),
                    mark(k, SL[k])))),
        # Phase D: the rest layer R = P[N].
        For("D.i", i, z3.IntVal(0), m, z3.And(ctx, layers_done(N), rows_done(N, i, spec_rest)),
            For("D.j", j, z3.IntVal(0), n,
                z3.And(ctx, 0 <= i, i < m, layers_done(N), rows_done(N, i, spec_rest),
                       cols_done(N, i, j, spec_rest)),
                mark(N, rest_read if rest_read is not None
                     else (rest_region if variant == "tight" else SL[N - 1])))),
    ))
    post = blocked_exact(P, d, motion=spec_motion, rest=spec_rest)
    return BuiltDRModel(program, sizes, post, d, P)


def _query(variant: str, kind: str, bug: str | None = None) -> Z3Query:
    model = builtdr_model(variant, bug=bug)
    return Z3Query(verification_conditions(f"BuiltDR.{variant}", model.pre, model.program,
                                           model.post, termination=kind == "termination"))


def _box_nesting() -> Z3Query:
    """spec.left_box's three rules for one joint at layer k, with the PTP motion of spec's
    left_angles: tight ⊆ modified ⊆ original. Quantifier-free polynomial real arithmetic."""
    s0, g0, w, dt, tf, k = z3.Reals("start goal omega dt Tf k")
    a0, a1 = z3.Reals("a_k a_k1")
    t0, t1 = k * dt, (k + 1) * dt

    def at(a: z3.ArithRef, t: z3.ArithRef) -> z3.BoolRef:
        # theta(t) = start + (goal - start) min(t/Tf, 1), multiplied out by Tf > 0.
        return z3.If(t >= tf, a == g0, tf * (a - s0) == (g0 - s0) * t)
    sign = z3.If(g0 > s0, z3.RealVal(1), z3.RealVal(-1))         # the s_q rule
    step = w * dt

    def lo_hi(x: z3.ArithRef, y: z3.ArithRef) -> tuple[z3.ArithRef, z3.ArithRef]:
        return z3.If(x <= y, x, y), z3.If(x <= y, y, x)
    orig = (a0 - step, a0 + step)
    mod = lo_hi(a0, a0 + sign * step)
    tight = lo_hi(a0, a1)
    base = (("omega > 0", w > 0), ("dt > 0", dt > 0), ("k >= 0", k >= 0),
            ("a_k = theta(k dt)", at(a0, t0)))
    speed = ("|goal - start| <= omega Tf (Tf = max_q |goal_q - start_q| / omega_q)",
             z3.And(tf > 0, g0 - s0 <= w * tf, s0 - g0 <= w * tf))
    outer = VC("modified_in_original", base, z3.And(orig[0] <= mod[0], mod[1] <= orig[1]),
               key_premise="omega > 0")
    inner = VC("tight_in_modified", base + (speed, ("a_k1 = theta((k+1) dt)", at(a1, t1))),
               z3.And(mod[0] <= tight[0], tight[1] <= mod[1]), key_premise=speed[0])
    return Z3Query((outer, inner))


def builtdr_obligations() -> list[Obligation]:
    """Theorem 1 (original), Theorem 3 (modified), and the tight variant: correctness and
    termination of BuiltDR."""
    P = Verdict.PROVED
    Z = Method.Z3
    term = ("BuiltDR terminates (for any N, m, n): each of its 7 loops has the variant "
            "hi - counter, >= 0 while the loop runs (from the guard) and lowered by every "
            "iteration, the invariant lo <= counter <= hi being inductive (VCs by WP). The "
            "termination is syntactic: every loop is a For loop whose body cannot change its "
            "counter or bounds (checked when the program is built), so the counter is bounded "
            "and increasing; no VC uses the precondition or the correctness invariants, and "
            "the main VC (the bounds hold on entry) is valid without its hypothesis.")
    out = []
    for ident, suffix, variant, ref, rest in (
            ("Thm1", "", "original", "Theorem 1 (Algorithm 1)", "the region of layer N-1"),
            ("Thm3", "", "modified", "Theorem 3 (Section IV.A)", "the region of layer N-1"),
            ("Thm3", "_tight", "tight", "Theorem 3, tight variant (docs/model.md §4)",
             "the principal at rest at its goal")):
        statement = (f"{{N >= 1, m, n >= 1}} BuiltDR ({variant}) {{for all k < N, i < m, j < n: "
                     f"P[k,i,j] = (SLarm_k ∩ SRarm_ij = Φ -> 0 | 1) with SLarm_k = "
                     f"regionL_{variant}(k), and the rest layer P[N,i,j] likewise with {rest}}}: "
                     "WP of the loop nest with invariants; Inter uninterpreted. Thm1.builtdr, "
                     "Thm3.builtdr and Thm3.builtdr_tight are the same proof over a different "
                     "opaque region function; what distinguishes the variants is the box "
                     "nesting (Thm3.box_nesting) and the per-scenario containment check "
                     "(Scenario.*.containment).")
        out.append(Obligation(f"{ident}.builtdr{suffix}", GROUP, ref, statement, Z, P,
                              lambda v=variant: _query(v, "correctness")))
        out.append(Obligation(f"{ident}.termination{suffix}", GROUP, ref, term, Z, P,
                              lambda v=variant: _query(v, "termination")))
    out.append(Obligation(
        "Thm3.box_nesting", GROUP, "Section IV.A (modified box), docs/model.md §4 (tight box)",
        "Per joint, for symbolic start, goal, omega > 0, dt > 0, layer k >= 0 and Tf with "
        "|goal - start| <= omega Tf: with a_k = theta(k dt) on the PTP motion theta(t) = start + "
        "(goal - start) min(t/Tf, 1), the tight box [min, max of a_k, a_k+1] lies within the "
        "modified box [a_k, a_k + s_q omega dt] (s_q = +1 if goal > start, else -1), which "
        "lies within the original box [a_k - omega dt, a_k + omega dt]: spec.left_box's rules. "
        "Quantifier-free polynomial real arithmetic (products of the symbols), no quantifier.",
        Z, P, _box_nesting))
    return out
