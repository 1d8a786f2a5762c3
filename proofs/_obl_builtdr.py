"""Theorem 1 and Theorem 3: BuiltDR's loop nest in the while-language, proved by WP and Z3.

The program is not written here: it is extracted (``proofs/_extract.py``) from the syntax tree of
``cfmpa.impl.builtdr_loop_nest``, BuiltDR in the paper's loop form: the left region of every
layer, the right region of every cell, then P[k, i, j] = (Inter(SL[k], SR[i, j]) -> 1 | 0) for
every cell of every layer, then the rest layer; its loop invariants are generated from it. Only
the pre- and postcondition are written here. Regions are values of an uninterpreted sort and the
intersection test an uninterpreted predicate, so the proof holds for any region function: the
original and the modified algorithm differ only in which one (``regionL_original`` vs
``regionL_modified``), and ``tight`` also in its rest layer (the principal at rest at its goal).
What tells the variants apart is read from their rules (``spec.Variant.rule``: the rest layer,
the theorems' numbers, the box nesting), never from their names (docs/model.md §4).
"""

from __future__ import annotations

import functools
import inspect
from dataclasses import dataclass

import z3

from ..impl import builtdr_loop_nest
from ..spec import Variant, ptp_angles
from ..spec.z3defs import REGION, Z3Dims, blocked_exact, inter
from ._extract import extract
from ._obligation import VC, Method, Obligation, Verdict, Z3Query
from ._while import Cmd, verification_conditions

__all__ = ["PLANTED_BUGS", "BuiltDRModel", "builtdr_model", "builtdr_obligations",
           "builtdr_source"]

GROUP = "BuiltDR (Theorems 1, 3)"

#: The variants whose rest layer is layer N - 1's region (the paper's) and those whose rest
#: layer is the principal at rest at its goal, by their rules.
_REST_N1 = tuple(v.value for v in Variant if not v.rest_at_goal)
_REST_GOAL = tuple(v.value for v in Variant if v.rest_at_goal)

#: Known defects planted in the loop form's source text, for the negative tests: name ->
#: (the variants it applies to, the (old, new) edits of the source).
PLANTED_BUGS: dict[str, tuple[tuple[str, ...], tuple[tuple[str, str], ...]]] = {
    # j runs to n - 1 in the motion layers.
    "inner_bound": (tuple(v.value for v in Variant), (
        ("for j in range(0, n):\n                if inter(SL[k]",
         "for j in range(0, n - 1):\n                if inter(SL[k]"),)),
    # A blocked motion cell is stored as free.
    "store_value": ((_REST_N1[0], *_REST_GOAL), (("P[k, i, j] = 1", "P[k, i, j] = 0"),)),
    # The rest layer reads layer 0's region instead of layer N - 1's.
    "rest_layer": (_REST_N1, (("else SL[N - 1]", "else SL[0]"),)),
    # A rest layer at the goal built from layer N - 1 (the paper's) instead of the principal
    # at rest.
    "tight_rest": (_REST_GOAL, (("region_rest() if rule.rest_at_goal else SL[N - 1]",
                                 "SL[N - 1]"),)),
    # The rest layer's rows stop at m - 1.
    "rest_rows": (_REST_N1[:1], (
        ("for i in range(0, m):\n        for j in range(0, n):\n"
         "            if inter(region_rest()",
         "for i in range(0, m - 1):\n        for j in range(0, n):\n"
         "            if inter(region_rest()"),)),
    # The motion layers start at 1.
    "layer_from_1": (_REST_N1[:1], (
        ("for k in range(0, N):\n        for i", "for k in range(1, N):\n        for i"),)),
}

#: A defect of the proof rather than of the program: C.j's invariant forgets the finished layers.
WEAK_INVARIANT = "weak_invariant"


def builtdr_source(bug: str | None = None) -> str:
    """The loop form's source text, with ``bug``'s edits applied (each must match)."""
    text = inspect.getsource(builtdr_loop_nest)
    if bug is None or bug == WEAK_INVARIANT:
        return text
    for old, new in PLANTED_BUGS[bug][1]:
        if old not in text:
            raise ValueError(f"planted bug {bug}: {old!r} is not in the loop form")
        text = text.replace(old, new)
    return text


@dataclass(frozen=True)
class BuiltDRModel:
    """The program, its pre- and postcondition, and the names it uses."""

    program: Cmd
    pre: z3.BoolRef
    post: z3.BoolRef
    dims: Z3Dims
    P: z3.ArrayRef


def builtdr_model(variant: str, *, bug: str | None = None, source: str | None = None
                  ) -> BuiltDRModel:
    """BuiltDR for ``variant`` (a ``spec.Variant`` value), extracted from the loop form (or
    from ``source``, a function's text). ``bug`` plants a known defect: a key of
    ``PLANTED_BUGS`` (an edit of the source) or ``weak_invariant`` (C.j's generated invariant
    forgets the finished layers)."""
    d = Z3Dims.named()
    N = d.N
    ints = z3.IntSort()
    P = z3.Array("P", ints, ints, ints, ints)
    regionL = z3.Function(f"regionL_{variant}", ints, REGION)
    regionR = z3.Function("regionR", ints, ints, REGION)
    if Variant(variant).rest_at_goal:
        rest_region: z3.ExprRef = z3.Const(f"regionRest_{variant}", REGION)
    else:
        # The paper's rest layer: the last motion layer's region.
        rest_region = regionL(N - 1)

    def spec_motion(kk: z3.ArithRef, ii: z3.ArithRef, jj: z3.ArithRef) -> z3.BoolRef:
        return inter(regionL(kk), regionR(ii, jj))

    def spec_rest(_: z3.ArithRef, ii: z3.ArithRef, jj: z3.ArithRef) -> z3.BoolRef:
        return inter(rest_region, regionR(ii, jj))

    sizes = d.sane()
    text = source if source is not None else builtdr_source(bug)
    forget = {"C.j"} if bug == WEAK_INVARIANT else set()
    program = extract(variant=variant, pre=sizes, dims=d, source=text, forget=forget).program
    post = blocked_exact(P, d, motion=spec_motion, rest=spec_rest)
    return BuiltDRModel(program, sizes, post, d, P)


def _query(variant: str, kind: str, bug: str | None = None, *, source: str | None = None
           ) -> Z3Query:
    model = builtdr_model(variant, bug=bug, source=source)
    from ._while import smoke_tests

    vcs = verification_conditions(f"BuiltDR.{variant}", model.pre, model.program,
                                  model.post, termination=kind == "termination")
    # The smoke tests go with the correctness proof (the termination proof's program is the
    # same, with the counters' bounds as its only invariants); small sizes pinned, where Z3
    # finds the models at once.
    d = model.dims
    small = tuple((x, z3.IntVal(2)) for x in (d.N, d.m, d.n))
    smoke = (() if kind == "termination"
             else smoke_tests(f"BuiltDR.{variant}", model.pre, model.program, witness=small))
    return Z3Query(vcs, smoke=smoke)


def _mentions(term: z3.ExprRef, const: z3.ExprRef) -> bool:
    """Whether ``const`` occurs in ``term``."""
    todo, seen = [term], set()
    while todo:
        e = todo.pop()
        if e.get_id() in seen:
            continue
        seen.add(e.get_id())
        if z3.eq(e, const):
            return True
        todo.extend(e.children())
    return False


def _box_nesting() -> Z3Query:
    """The code's box rules (spec.Variant's rule table, which spec.left_box, impl and Safety
    read) run on Z3 terms for one joint at layer k, with a_k, a_k+1 on the PTP motion of
    spec.ptp_angles (spec.left_angles'): each variant's box within its rule's ``within``
    (``Variant.nesting``: tight ⊆ modified ⊆ original), one VC a pair, outermost first. A pair
    whose boxes read a_k+1 also gets a_k+1 on the motion and the speed bound as premises. A
    changed rule changes the statement; a rule that no longer nests fails it. Quantifier-free
    nonlinear real arithmetic."""
    s0, g0, w, dt, tf, k = z3.Reals("start goal omega dt Tf k")
    a0, a1 = z3.Reals("a_k a_k1")

    def theta(t: z3.ArithRef) -> z3.ArithRef:
        # spec.ptp_angles on the symbols (both joints alike; joint 1 read).
        return ptp_angles((s0, s0), (g0, g0), tf, t)[0]
    step, up = w * dt, g0 > s0
    base = (("omega > 0", w > 0), ("dt > 0", dt > 0), ("k >= 0", k >= 0),
            ("a_k = theta(k dt) (spec.ptp_angles)", a0 == theta(k * dt)))
    speed = ("|goal - start| <= omega Tf (Tf = max_q |goal_q - start_q| / omega_q)",
             z3.And(tf > 0, g0 - s0 <= w * tf, s0 - g0 <= w * tf))
    nxt = ("a_k1 = theta((k+1) dt) (spec.ptp_angles)", a1 == theta((k + 1) * dt))
    vcs = []
    for inner, outer in reversed(Variant.nesting()):
        small, big = inner.joint_box(a0, a1, step, up), outer.joint_box(a0, a1, step, up)
        goal = z3.And(big[0] <= small[0], small[1] <= big[1])
        if any(_mentions(x, a1) for x in (*small, *big)):
            vcs.append(VC(f"{inner}_in_{outer}", base + (speed, nxt), goal,
                          key_premise=speed[0]))
        else:
            vcs.append(VC(f"{inner}_in_{outer}", base, goal, key_premise="omega > 0"))
    return Z3Query(tuple(vcs))


#: The gist of each variant's region in the obligations' summaries (a variant without one is
#: described by its rule's words).
_WHAT = {Variant.ORIGINAL: "Theorem 1, the paper's original region",
         Variant.MODIFIED: "Theorem 3, the paper's modified, one-sided region",
         Variant.TIGHT: "tight: swept between two instants only"}


def theorem_of(v: Variant) -> tuple[str, str, str]:
    """(the variant's value, ``Thm<n>`` of its BuiltDR theorem, the id suffix: none for a
    variant of the paper, else ``_<variant>``), read from its rule."""
    return v.value, f"Thm{v.rule.theorems[0]}", "" if v.rule.in_paper else f"_{v}"


def builtdr_obligations() -> list[Obligation]:
    """Theorem 1 (original), Theorem 3 (modified), and the tight variant: correctness and
    termination of BuiltDR."""
    P = Verdict.PROVED
    Z = Method.Z3
    term = ("BuiltDR terminates (for any N, m, n): each of its 8 loops (A.k .. D.j) has the "
            "variant hi - counter, >= 0 while the loop runs (from the guard) and lowered by every "
            "iteration, the invariant lo <= counter <= hi being inductive (VCs by WP). The "
            "termination is syntactic: every loop is a For loop whose body cannot change its "
            "counter or bounds (checked when the program is built), so the counter is bounded "
            "and increasing; no VC uses the precondition or the correctness invariants, and "
            "the main VC (the bounds hold on entry) is valid without its hypothesis.")
    out = []
    names = [f"{ident}.builtdr{suffix}" for _, ident, suffix in map(theorem_of, Variant)]
    same = ", ".join(names[:-1]) + " and " + names[-1]
    for v in Variant:
        variant, ident, suffix = theorem_of(v)
        r = v.rule
        ref = (f"Theorem {r.theorems[0]} ({r.source})" if r.in_paper
               else f"Theorem {r.theorems[0]}, {v} variant ({r.source})")
        rest = ("the principal at rest at its goal" if r.rest_at_goal
                else "the region of layer N-1")
        what = _WHAT.get(v, f"{v}: {r.words}")
        statement = (f"{{N >= 1, m, n >= 1}} BuiltDR ({variant}) {{for all k < N, i < m, j < n: "
                     f"P[k,i,j] = (SLarm_k ∩ SRarm_ij = Φ -> 0 | 1) with SLarm_k = "
                     f"regionL_{variant}(k), and the rest layer P[N,i,j] likewise with {rest}}}: "
                     "WP of the while program extracted from the loop form "
                     "(cfmpa.impl.builtdr_loop_nest, Algorithm 1 as written), with loop "
                     f"invariants generated from it; Inter uninterpreted. {same} are the "
                     "same proof over a different "
                     "opaque region function; what distinguishes the variants is the box "
                     "nesting (Thm3.box_nesting) and the per-scenario containment check "
                     "(Scenario.*.containment).")
        out.append(Obligation(f"{ident}.builtdr{suffix}", GROUP, ref, statement, Z, P,
                              functools.partial(_query, variant, "correctness"),
                              summary=("BuiltDR as written in Algorithm 1 marks a cell of D_R "
                                       "blocked exactly when the subordinate arm at that cell "
                                       "meets the principal arm's swept region of that time "
                                       f"step ({what}).")))
        out.append(Obligation(f"{ident}.termination{suffix}", GROUP, ref, term, Z, P,
                              functools.partial(_query, variant, "termination"), label="syntactic",
                              definitional="a termination measure: counted loops end",
                              summary=(f"BuiltDR ({variant}) always stops: each of its loops "
                                       "counts up to a bound fixed before it starts, and "
                                       "nothing inside a loop changes its counter or bound.")))
    out.append(Obligation(
        "Thm3.box_nesting", GROUP, "Section IV.A (modified box), docs/model.md §4 (tight box)",
        "Per joint, for symbolic start, goal, omega > 0, dt > 0, layer k >= 0 and Tf with "
        "|goal - start| <= omega Tf: with a_k = theta(k dt) on the PTP motion theta(t) = start + "
        "(goal - start) min(t/Tf, 1), the tight box [min, max of a_k, a_k+1] lies within the "
        "modified box [a_k, a_k + s_q omega dt] (s_q = +1 if goal > start, else -1), which "
        "lies within the original box [a_k - omega dt, a_k + omega dt]: spec.left_box's rules, "
        "the code's own (spec.Variant's rule table run on Z3 terms, theta by spec.ptp_angles), "
        "so a changed rule changes the statement and a rule that no longer nests fails it. "
        "Quantifier-free nonlinear real arithmetic, no quantifier.",
        Z, P, _box_nesting,
        summary=("Per joint and time step, the tight variant's box of principal angles lies inside "
                 "the modified one, which lies inside the original one: each variant sweeps no "
                 "more than the one before.")))
    return out
