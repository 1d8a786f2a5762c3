"""Margin.arc_chord, as proved (docs/model.md §4, §10): its VC read back from the prove run's
obligation in abstract norms, and its goal in three smaller lemmas the region proofs use.
"""

from __future__ import annotations

from dataclasses import dataclass

import z3

from ._lemmas import Lemma, lemma, obligation_vc
from ._obl_margin import margin_obligations
from ._obligation import VC
from ._z3vec import SQ, Vec, concrete

__all__ = ["ArcChord", "abstract_norms", "arc_chord", "arc_steps"]

def abstract_norms(f: z3.ExprRef) -> z3.ExprRef:
    """f with every a*a + b*b (as Margin's _n2 builds it) written sq(a, b)."""
    if z3.is_add(f) and f.num_args() == 2:
        a, b = f.arg(0), f.arg(1)
        if (z3.is_mul(a) and z3.is_mul(b) and a.num_args() == 2 and b.num_args() == 2
                and z3.eq(a.arg(0), a.arg(1)) and z3.eq(b.arg(0), b.arg(1))):
            return SQ(abstract_norms(a.arg(0)), abstract_norms(b.arg(0)))
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
        vc = obligation_vc("Margin.arc_chord", "arc_within_chord", margin_obligations())
    r, g, c, s, cp, sp = z3.Reals("r g c s c_psi s_psi")
    goal = abstract_norms(vc.goal)
    bad = ValueError("Margin.arc_chord's goal is not 0 <= t <= 1 and |m - q|^2 <= delta^2")
    if not (z3.is_and(goal) and goal.num_args() == 3):
        raise bad
    lo, hi, bound = goal.children()
    t = hi.arg(0)
    lhs, rhs = bound.arg(0), bound.arg(1)
    if not (z3.is_le(hi) and z3.is_ge(lo) and z3.eq(lo.arg(0), t) and z3.is_le(bound)
            and lhs.decl().eq(SQ) and z3.is_mul(rhs) and rhs.num_args() == 2
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
